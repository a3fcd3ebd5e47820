#pragma once
// EnKBF: the ensemble Kalman-Bucy filter, N ensemble members per bank member (`--enkbf-particles`), each
// following the model's own dynamics and pulled towards the observations with a gain made from ensemble
// statistics (Evensen 1994; continuous time: Bergemann and Reich 2012; the forms below as in Taghvaei, de Wiljes,
// Mehta and Reich 2018, "Kalman filter and its modern extensions for the continuous-time nonlinear filtering
// problem"):
//   dX_i = f(X_i) dt + G dW_i + K (dy - h(X_i) dt - R dV_i),         K = P^{xh} V^{-1}    (EnKBF-S: stochastic,
//                                                                                          perturbed observations)
//   dX_i = f(X_i) dt + G dW_i + K (dy - 1/2 (h(X_i) + h_bar) dt)                          (EnKBF: deterministic
//                                                                                          innovation, Bergemann-Reich)
// with P^{xh}, h_bar the ensemble's covariance of x with h(x) and mean of h(x); W_i, V_i independent Brownian
// motions per ensemble member. Both variants sample the process noise. The bank reports the ensemble's mean
// and covariance (divisor N - 1) as m and P.
// One step of the bank's discretization (kernels/filters/filter_step.hpp): the update with dy uses the ensemble
// statistics of the step's start, S = V + dt P^{hh}, K = P^{xh} S^{-1} (the discrete ensemble Kalman update of
// the observation dy with noise V dt), then every member takes its Euler-Maruyama step. On a linear model the
// stochastic variant's mean and covariance equal the Kalman-Bucy step's in expectation, so as N grows it tends to
// Kalman-Bucy with Monte Carlo error of order N^{-1/2}; the deterministic one has the same limit up to O(dt) (its
// half-gain step contracts the spread by (I - dt K H / 2)^2, not I - dt K H).
// Random numbers: initial ensemble from N(prior mean, prior cov) on Stream::filter_initial, process noise (and
// before it, in the stochastic variant, the observation perturbation: observation_and_process_normals) on
// Stream::filter_noise, each keyed by the run's seed with counter {member, ensemble member, step}.
// A GPU thread moves its member's ensemble one member after the other; on the host the ensemble members move in SIMD
// lanes (move_in_lanes), their normals drawn first in a loop of their own (the same Philox numbers; glibc's vector
// log, sin and cos, within a few ulp of libm's).
#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "kernels/filters/filter_protocol.hpp"
#include "kernels/filters/filter_step.hpp"
#include "kernels/for_each_member.hpp"
#include "kernels/particle_filter/particle_draws.hpp"
#include "kernels/rng.hpp"

#include <Kokkos_Core.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

namespace kushner {

template <class Model, class MemSpace, bool Stochastic>
struct EnsembleKalmanBucyBase {
  static constexpr int n = Model::state_dim, p = Model::obs_dim, q = Model::noise_dim;
  static constexpr const char* unsupported = nullptr;  // needs only f, G and h
  static constexpr bool randomized = true;

  int num_particles = 0;
  Seed seed;
  Kokkos::View<double***, Kokkos::LayoutLeft, MemSpace> ensemble;  // (member, ensemble member, i)

  /// The state a checkpoint holds beyond m and P (engine/state_archive.hpp).
  template <class Archive>
  void visit_state(Archive& archive) {
    archive.view("ensemble", ensemble);
  }
  static double own_bytes_per_member(const OptionValues& options) {
    return sizeof(double) * n * static_cast<double>(options.integer("enkbf_particles"));
  }

  static std::vector<OptionSpec> options() {
    return {OptionSpec::integer("enkbf_particles", 100, 2, 1 << 20,
                                "ensemble members per bank member of EnKBF and EnKBF-S")};
  }

  /// The initial ensemble: num_particles draws from N(prior_mean, prior_cov) per member.
  static void initialize(EnsembleKalmanBucyBase& f, const Model& model, long members, long particles, Seed seed) {
    f.num_particles = static_cast<int>(particles);
    f.seed = seed;
    f.ensemble = decltype(f.ensemble)(Kokkos::view_alloc(Kokkos::WithoutInitializing, "kushner::enkbf_ensemble"),
                                      members, particles, n);
    Mat<n, n> L;
    KUSHNER_REQUIRE(semidefinite_cholesky(model.prior_cov, L, covariance_tolerance) != Definiteness::indefinite,
                    "EnKBF: prior_cov is not positive semidefinite");
    auto host = Kokkos::create_mirror_view(f.ensemble);
    const RngKey key{seed, Stream::filter_initial};
    for (long member = 0; member < members; ++member)
      for (long k = 0; k < particles; ++k) {
        const Vec<n> x = model.prior_mean + L * normal_vector<n>(key, static_cast<std::uint32_t>(member),
                                                                 static_cast<std::uint32_t>(k), 0);
        for (int i = 0; i < n; ++i) host(member, k, i) = x[i];
      }
    Kokkos::deep_copy(f.ensemble, host);
  }

  Fields summary_fields() const {
    return {{"particles", static_cast<long>(num_particles)},
            {"variant", std::string(Stochastic ? "stochastic" : "deterministic")}};
  }

  KOKKOS_INLINE_FUNCTION Vec<n> load_member(int member, int k) const {
    Vec<n> x;
    for (int i = 0; i < n; ++i) x[i] = ensemble(member, k, i);
    return x;
  }

  /// A closed loop's known input B u dt moves every ensemble member alike (its Euler step is x + (f + B u) dt + ...).
  KOKKOS_INLINE_FUNCTION void apply_known_input(int member, const Vec<n>& shift) const {
    for (int k = 0; k < num_particles; ++k)
      for (int i = 0; i < n; ++i) ensemble(member, k, i) += shift[i];
  }

  KOKKOS_INLINE_FUNCTION Status step(const Model& model, int member, const StepInput<p>& in, Vec<n>& m,
                                     Mat<n, n>& P) const {
    const int N = num_particles;
    const std::uint32_t step_index = in.step;
    const auto who = static_cast<std::uint32_t>(member);
    // Ensemble statistics at the step's start: x_bar, h_bar, P^{xh}, P^{hh} (two passes: means, then spreads).
    Vec<n> x_bar = Vec<n>::zero();
    Vec<p> h_bar = Vec<p>::zero();
    for (int k = 0; k < N; ++k) {
      const Vec<n> x = load_member(member, k);
      x_bar += x;
      h_bar += model.observation(in.t, x);
    }
    x_bar = x_bar * (1.0 / N);
    h_bar = h_bar * (1.0 / N);
    Mat<n, p> Pxh = Mat<n, p>::zero();
    Mat<p, p> Phh = Mat<p, p>::zero();
    for (int k = 0; k < N; ++k) {
      const Vec<n> x = load_member(member, k);
      const Vec<p> dh = model.observation(in.t, x) - h_bar;
      Pxh += outer(x - x_bar, dh);
      Phh += outer(dh, dh);
    }
    Pxh = Pxh * (1.0 / (N - 1));
    Phh = Phh * (1.0 / (N - 1));
    const Mat<p, p> S = in.V + Phh * in.dt;
    PositiveDefiniteSolver<p> solver;
    Mat<p, p> LV;
    if (!solver.factor(S) || !cholesky(in.V, LV)) return Status::not_positive_definite;
    const Mat<n, p> K = solver.right_solve(Pxh);  // P^{xh} S^{-1}
    // Update and Euler-Maruyama step of every ensemble member.
    const double sqrt_dt = math::sqrt(in.dt);
    const RngKey noise_key{seed, Stream::filter_noise};
    bool moved = false;
#if !KUSHNER_CUDA_DEVICE_PASS
    if constexpr (Kokkos::SpaceAccessibility<Kokkos::HostSpace, MemSpace>::accessible) {
      move_in_lanes(model, member, in, K, LV, h_bar, sqrt_dt, noise_key, who, step_index);
      moved = true;
    }
#endif
    if (!moved) {
      for (int k = 0; k < N; ++k) {
        Vec<n> x = load_member(member, k);
        const auto ensemble_member = static_cast<std::uint32_t>(k);
        Vec<p> zv = Vec<p>::zero();
        Vec<q> zw;
        if constexpr (Stochastic)
          observation_and_process_normals<p, q>(noise_key, who, ensemble_member, step_index, zv, zw);
        else
          zw = normal_vector<q>(noise_key, who, ensemble_member, step_index);
        move(model, in, K, LV, h_bar, sqrt_dt, zv, zw, x);
        for (int i = 0; i < n; ++i) ensemble(member, k, i) = x[i];
      }
    }
    // The new mean and covariance.
    Vec<n> sum = Vec<n>::zero();
    for (int k = 0; k < N; ++k) sum += load_member(member, k);
    m = sum * (1.0 / N);
    Mat<n, n> cov = Mat<n, n>::zero();
    for (int k = 0; k < N; ++k) {
      const Vec<n> d = load_member(member, k) - m;
      cov += outer(d, d);
    }
    P = symmetrize(cov * (1.0 / (N - 1)));
    return Status::ok;
  }

 private:
  /// One ensemble member's update with dy and its Euler-Maruyama step, given its normals: zv the observation
  /// perturbation's (stochastic variant), zw the process noise's.
  KOKKOS_INLINE_FUNCTION void move(const Model& model, const StepInput<p>& in, const Mat<n, p>& K, const Mat<p, p>& LV,
                                   const Vec<p>& h_bar, const double sqrt_dt, const Vec<p>& zv, const Vec<q>& zw,
                                   Vec<n>& x) const {
    const Vec<p> hx = model.observation(in.t, x);
    Vec<p> innovation;
    if constexpr (Stochastic)
      innovation = in.dy - hx * in.dt - LV * zv * sqrt_dt;
    else
      innovation = in.dy - (hx + h_bar) * (0.5 * in.dt);
    x += K * innovation;
    x += model.drift(in.t, x, Model::Control::zero()) * in.dt + model.diffusion(in.t, x) * zw * sqrt_dt;
  }

  /// An ensemble member's normals on the host: the stochastic variant's v and w (observation_and_process_normals'),
  /// or w alone (normal_vector<q>'s), in their layout.
  using LaneLayout = ObservationAndProcessLayout<Stochastic ? p : 0, q>;

  /// Host: every ensemble member's move, host_member_chunk of them at a time in SIMD lanes: their normals first
  /// (draw_normal_lanes: the same numbers as normal_vector, Box-Muller in SIMD lanes), then the moves. The
  /// stochastic EnKBF's scalar draws and drift (libm's log, cos, sin per ensemble member) took 62% of `kushner
  /// compare`'s default run.
  void move_in_lanes(const Model& model, const int member, const StepInput<p>& in, const Mat<n, p>& K,
                     const Mat<p, p>& LV, const Vec<p>& h_bar, const double sqrt_dt, const RngKey& noise_key,
                     const std::uint32_t who, const std::uint32_t step_index) const {
    constexpr int chunk = host_member_chunk;
    constexpr int draws = LaneLayout::normals;
    double* const xs = &ensemble(member, 0, 0);  // raw: GCC does not vectorize a loop that reloads a View's pointer
    const std::size_t k_stride = ensemble.stride(1), i_stride = ensemble.stride(2);
    for (int begin = 0; begin < num_particles; begin += chunk) {
      const int end = host_chunk_end(begin, num_particles);
      double z[draws * chunk];
      const Counter first{who, static_cast<std::uint32_t>(begin), step_index, 0};
      draw_normal_lanes<draws>(noise_key, {first, Counter{0, 1, 0, 0}}, end - begin, z, chunk);
      KUSHNER_SIMD
      for (int k = begin; k < end; ++k)
        move_lane(model, in, K, LV, h_bar, sqrt_dt, xs + k * k_stride, i_stride, z + (k - begin));
    }
  }

  /// move() of the ensemble member at x[i * i_stride] with its normals at z[j * host_member_chunk]: the loop body of
  /// move_in_lanes as one call with scalar arguments (a Vec local to the body becomes an `omp simd` array, which
  /// GCC does not vectorize).
  KOKKOS_INLINE_FUNCTION void move_lane(const Model& model, const StepInput<p>& in, const Mat<n, p>& K,
                                        const Mat<p, p>& LV, const Vec<p>& h_bar, const double sqrt_dt, double* const x,
                                        const std::size_t i_stride, const double* const z) const {
    Vec<n> xk;
    Vec<q> zw;
    Vec<p> zv = Vec<p>::zero();
    for (int i = 0; i < n; ++i) xk[i] = x[i * i_stride];
    if constexpr (Stochastic)
      for (int j = 0; j < p; ++j) zv[j] = z[(LaneLayout::v + j) * host_member_chunk];
    for (int j = 0; j < q; ++j) zw[j] = z[(LaneLayout::w + j) * host_member_chunk];
    move(model, in, K, LV, h_bar, sqrt_dt, zv, zw, xk);
    for (int i = 0; i < n; ++i) x[i * i_stride] = xk[i];
  }
};

template <class Model, class MemSpace>
struct EnsembleKalmanBucyFilter : EnsembleKalmanBucyBase<Model, MemSpace, false> {
  static constexpr const char* name = "EnKBF";
  static constexpr const char* description =
      "ensemble Kalman-Bucy filter, deterministic innovation (Bergemann-Reich), --enkbf-particles members";

  static EnsembleKalmanBucyFilter create(const OptionValues& options, const Model& model, long members, Seed seed) {
    EnsembleKalmanBucyFilter f;
    EnsembleKalmanBucyFilter::initialize(f, model, members, options.integer("enkbf_particles"), seed);
    return f;
  }
};

template <class Model, class MemSpace>
struct StochasticEnsembleKalmanBucyFilter : EnsembleKalmanBucyBase<Model, MemSpace, true> {
  static constexpr const char* name = "EnKBF-S";
  static constexpr const char* description =
      "ensemble Kalman-Bucy filter, perturbed observations (stochastic), --enkbf-particles members";

  static StochasticEnsembleKalmanBucyFilter create(const OptionValues& options, const Model& model, long members,
                                                   Seed seed) {
    StochasticEnsembleKalmanBucyFilter f;
    StochasticEnsembleKalmanBucyFilter::initialize(f, model, members, options.integer("enkbf_particles"), seed);
    return f;
  }
};

}  // namespace kushner
