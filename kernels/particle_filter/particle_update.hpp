#pragma once
// One particle's step of the bootstrap particle filter (Gordon, Salmond & Smith 1993; continuous-time
// observations as in Bain & Crisan 2009, ch. 9): propagate with the model's Euler-Maruyama step (or its exact
// transition), then multiply the weight by the likelihood of the member's observation increment,
//   log g(dy | x) = h(x)^T V^{-1} dy - (dt / 2) h(x)^T V^{-1} h(x) + const,   V = R R^T,
// which is -|dy - h dt|^2_{(V dt)^{-1}} / 2 up to a constant of the member. A discrete-time model's particle
// takes x <- F(k, x, u) + w (the model's process_noise from the particle's draws) and the weight the density of
// v at z[k+1] - h(k+1, x) (zero outside a bounded noise's support). Every step kernel (the host's
// block kernel, the GPU's one-step and fused two-step team kernels) calls update_particle, with the draws
// of particle_draws.hpp.
#include "core/linear_algebra.hpp"
#include "core/math.hpp"
#include "core/portability.hpp"
#include "core/status.hpp"
#include "kernels/bank.hpp"
#include "kernels/particle_filter/particle_draws.hpp"
#include "kernels/particle_filter/particle_model_traits.hpp"
#include "kernels/particle_filter/simd_random.hpp"
#include "kernels/particle_filter/weighted_moments.hpp"
#include "kernels/rng.hpp"

#include <Kokkos_Core.hpp>

#include <cmath>
#include <cstdint>
#include <type_traits>

namespace kushner {

/// V^{-1} at a step's time, and its entries rounded once to float for a step computed in float (fp32): converted in
/// the kernel, they took a conversion each for every particle, as dt did (ParticleStepData::set_step_length).
template <int P>
struct ObservationPrecision {
  Mat<P, P> value;
  Mat<P, P, float> value_float;

  ObservationPrecision() = default;
  ObservationPrecision(const Mat<P, P>& precision)  // NOLINT(google-explicit-constructor): assigned as a Mat
      : value(precision), value_float(convert<float>(precision)) {}

  /// V^{-1} in the scalar S a particle's step is computed in.
  template <class S>
  KOKKOS_INLINE_FUNCTION const Mat<P, P, S>& as() const {
    if constexpr (std::is_same_v<S, float>)
      return value_float;
    else
      return value;
  }
};

/// Everything one step reads and writes. Views are (particle, member[, i]) or (member[, i]), LayoutLeft. The
/// particles and log-weights are stored as Real (float in the fp32 precision: particle_precision.hpp); a particle's
/// step computes in particle_step_scalar<Model, Real>.
template <class Model, class MemSpace, class Real = double>
struct ParticleStepData {
  static constexpr int n = Model::state_dim, p = Model::obs_dim, q = Model::noise_dim;
  Model model;
  ParticleBank<MemSpace, Real> x;               // (particle, member, i)
  ParticleColumn<MemSpace, Real> log_weight;    // (particle, member)
  BankScalar<double, MemSpace> log_normalizer;  // log sum_j exp(log_weight_j)
  BankVector<MemSpace> reference;               // (member, i): previous posterior mean
  BankVector<MemSpace> dy;                      // (member, j): this step's increments
  BankScalar<Status, MemSpace> status;
  BankVector<MemSpace> control;  // (member, j): the control over this step (closed loop); empty: none
  Kokkos::View<double***, Kokkos::LayoutLeft, MemSpace> partials;  // (block, member, k)
  ObservationPrecision<p> observation_precision;                   // (R R^T)^{-1} at t
  Vec<n> initial_mean;
  Mat<n, n> initial_root;  // any square root of the initial covariance
  double t = 0.0, dt = 0.0;
  double sqrt_dt = 0.0;  // computed once: nvcc re-evaluated sqrt(dt) for every particle
  // dt, sqrt(dt) and dt / 2 rounded once for a step computed in float (fp32): converted in the kernel, they took a
  // conversion each for every particle (nvcc rematerializes them from the constant bank rather than hold registers).
  float dt_float = 0.0f, sqrt_dt_float = 0.0f, half_dt_float = 0.0f;
  Seed seed;
  std::uint32_t step = 0;
  int num_particles = 0, block_size = 0;
  bool initialize = false;    // sample the initial law instead of propagating; no observation
  bool fp32_normals = false;  // the `mixed` and `fp32` precisions (particle_precision.hpp)

  /// Whether the normals are drawn in float: always where particles are stored in float, which the compiler then
  /// knows (fp32's kernels carry no fp64 Box-Muller), else as fp32_normals says.
  KOKKOS_INLINE_FUNCTION bool float_normals() const { return std::is_same_v<Real, float> || fp32_normals; }

  /// Whether a particle's Euler-Maruyama increment f dt + G dw is computed in float and added to its double state:
  /// the `mixed` precision, for a model whose increments can be taken in float (has_float_increments). Kernels take
  /// it as their FloatIncrements parameter (update_particle), not from here at every particle.
  KOKKOS_INLINE_FUNCTION bool float_increments() const { return has_mixed_increments<Model, Real> && fp32_normals; }

  /// Sets the step's length dt and what the kernels take from it.
  void set_step_length(const double step_length) {
    dt = step_length;
    sqrt_dt = std::sqrt(step_length);
    dt_float = static_cast<float>(dt);
    sqrt_dt_float = static_cast<float>(sqrt_dt);
    half_dt_float = static_cast<float>(0.5 * dt);
  }

  /// dt, sqrt(dt) and dt / 2 in the scalar S a particle's step is computed in: each is the double rounded to S.
  template <class S>
  KOKKOS_INLINE_FUNCTION S dt_as() const {
    return in_scalar<S>(dt, dt_float);
  }
  template <class S>
  KOKKOS_INLINE_FUNCTION S sqrt_dt_as() const {
    return in_scalar<S>(sqrt_dt, sqrt_dt_float);
  }
  template <class S>
  KOKKOS_INLINE_FUNCTION S half_dt_as() const {
    return in_scalar<S>(0.5 * dt, half_dt_float);
  }

 private:
  template <class S>
  KOKKOS_INLINE_FUNCTION static S in_scalar(double as_double, float as_float) {
    if constexpr (std::is_same_v<S, float>)
      return as_float;
    else
      return as_double;
  }
};

/// The second step of a fused pair (particle_team_pair_step.hpp): step + 1, over [t, t + dt]. The pair reads the
/// first step's x and log_weight and writes x and log_weight here (same layout), so that its first step can be
/// recomputed from untouched inputs.
template <class Model, class MemSpace, class Real = double>
struct ParticleSecondStep {
  static constexpr int p = Model::obs_dim;
  ParticleBank<MemSpace, Real> x;
  ParticleColumn<MemSpace, Real> log_weight;
  BankVector<MemSpace> dy;
  Kokkos::View<double***, Kokkos::LayoutLeft, MemSpace> partials;
  ObservationPrecision<p> observation_precision;
  double t = 0.0;
};

/// Draws per particle and step: the normals of the initial state, or of the Euler-Maruyama step.
template <class Model, bool Initialize>
constexpr int particle_draw_dim = Initialize ? Model::state_dim : Model::noise_dim;

template <class Model, bool Initialize>
constexpr bool draws_uniform = !Initialize && (Model::discrete_time || has_exact_transition<Model>::value);

/// The key and step of the particles' draws: their initial states, or step d.step.
template <bool Initialize, class Model, class MemSpace, class Real>
KOKKOS_INLINE_FUNCTION RngKey particle_draw_key(const ParticleStepData<Model, MemSpace, Real>& d) {
  return RngKey{d.seed, Initialize ? Stream::particle_initial : Stream::particle_noise};
}
template <bool Initialize, class Model, class MemSpace, class Real>
KOKKOS_INLINE_FUNCTION std::uint32_t particle_draw_step(const ParticleStepData<Model, MemSpace, Real>& d) {
  return Initialize ? 0 : d.step;
}

/// Whether a step's normals are the `fp32` precision's (fp32_pair_normals: two steps share a Philox block): those of
/// a bank that stores its particles in float, but not its initial particles (mixed's).
template <class Real, bool Initialize>
constexpr bool fp32_step_draws = std::is_same_v<Real, float> && !Initialize;

/// The draws of particles 2 pair (z0, u0) and 2 pair + 1 (z1, u1) of `member` at `step`, from Philox (philox_block:
/// the team kernels; the host kernel draws a block's lanes at once with simd::uniform_pair_lanes, the same bits);
/// normals in float with `fp32` (ParticleStepData::float_normals, the same for every thread: no divergence), and
/// fp32_pair_normals with Fp32Steps (fp32_step_draws).
template <class Model, bool Initialize, bool Fp32Steps = false>
KOKKOS_INLINE_FUNCTION void draw_particle_pair(const RngKey& key, int member, int pair, std::uint32_t step, bool fp32,
                                               Vec<particle_draw_dim<Model, Initialize>>& z0,
                                               Vec<particle_draw_dim<Model, Initialize>>& z1, double& u0, double& u1) {
  constexpr int K = particle_draw_dim<Model, Initialize>;
  KUSHNER_DEVICE_UNROLL
  for (int i = 0; i < K; ++i) {
    NormalPair zi;
    if constexpr (Fp32Steps)
      zi = fp32_pair_normals(key, member, pair, step, i);
    else
      zi = fp32 ? pair_normals<true>(key, member, pair, step, i) : pair_normals(key, member, pair, step, i);
    z0[i] = zi.z0;
    z1[i] = zi.z1;
  }
  u0 = u1 = 0.0;
  if constexpr (draws_uniform<Model, Initialize>) pair_uniforms(key, member, pair, step, K, u0, u1);
}

/// V^{-1} dy of one member: the only observation term the likelihood needs besides h(x).
template <class Model, class MemSpace, class Real>
KOKKOS_INLINE_FUNCTION Vec<Model::obs_dim> precision_times_dy(const ParticleStepData<Model, MemSpace, Real>& d,
                                                              int member) {
  return d.observation_precision.value * load<Model::obs_dim>(d.dy, member);
}

/// The control a member's particles are driven by over this step (zero outside a closed loop).
template <class Model, class MemSpace, class Real>
KOKKOS_INLINE_FUNCTION typename Model::Control particle_control(const ParticleStepData<Model, MemSpace, Real>& d,
                                                                int member) {
  if constexpr (Model::control_dim > 0) {
    if (d.control.extent(0) > 0) return load<Model::control_dim>(d.control, member);
  }
  return Model::Control::zero();
}

/// l, or -inf where l or a component of x is not finite: a particle that left the numbers. `&`, not `&&`: no branch, so
/// GCC can vectorize the host's loops.
template <class S, int N>
KOKKOS_INLINE_FUNCTION S finite_or_dead(const S l, const Vec<N, S>& x) {
  bool finite = math::is_finite(l);
  KUSHNER_UNROLL_FULLY
  for (int i = 0; i < N; ++i) finite = finite & math::is_finite(x[i]);
  return finite ? l : -static_cast<S>(math::infinity());
}

/// A particle's new state x and log-weight l as the bank stores them (stored_value, kernels/bank.hpp); returns l, or
/// -inf where x left float's range (stored as inf: the particle has left the numbers). Nothing to do for double.
/// The host's block kernel applies the same rule in loops of its own (particle_block_step.hpp: GCC vectorizes
/// those).
template <class Real, int N>
KOKKOS_INLINE_FUNCTION double round_to_storage(Vec<N>& x, double l) {
  if constexpr (std::is_same_v<Real, double>) {
    return l;
  } else {
    bool finite = true;
    KUSHNER_UNROLL_FULLY
    for (int i = 0; i < N; ++i) {
      x[i] = stored_value<Real>(x[i]);
      finite = finite & math::is_finite(x[i]);
    }
    return finite ? stored_value<Real>(l) : -math::infinity();
  }
}

namespace detail {
/// x + f(t, x) dt + G(t, x) sqrt(dt) z in S; with FloatIncrements (`mixed`: ParticleStepData::float_increments) the
/// increment f dt + G sqrt(dt) z is computed in float, from x rounded to float, and added to x in double: it moves
/// by about 6e-8 of itself and of |x f'(x)| dt, as much as the float normal's rounding moves it, and the state keeps
/// double's precision over many steps (tests/test_particle_filter.cpp, MixedTakesFloatIncrementsOfADoubleState).
template <bool FloatIncrements, class S, class Model, class MemSpace, class Real, int K>
KOKKOS_INLINE_FUNCTION Vec<Model::state_dim, S> euler_maruyama_step(const ParticleStepData<Model, MemSpace, Real>& d,
                                                                    double t, const Vec<Model::state_dim, S>& x,
                                                                    const Vec<K>& z,
                                                                    const typename Model::Control& control) {
  if constexpr (FloatIncrements) {
    static_assert(has_mixed_increments<Model, S>, "float increments of a double state");
    const Vec<Model::state_dim, float> xf = convert<float>(x);
    const Vec<Model::state_dim, float> dx =
        d.model.drift(t, xf, control) * d.template dt_as<float>() +
        d.model.diffusion(t, xf) * (convert<float>(z) * d.template sqrt_dt_as<float>());
    return x + convert<double>(dx);
  } else {
    return x + d.model.drift(t, x, control) * d.template dt_as<S>() +
           d.model.diffusion(t, x) * (convert<S>(z) * d.template sqrt_dt_as<S>());
  }
}

/// A continuous-time particle's step in S (particle_step_scalar): xs moved by the model's exact transition or its
/// Euler-Maruyama step, and its new log-weight, before the check that both are finite.
template <bool FloatIncrements, class S, class Model, class MemSpace, class Real, class P>
KOKKOS_FORCEINLINE_FUNCTION S continuous_time_step(
    const ParticleStepData<Model, MemSpace, Real>& d, double t, const Mat<Model::obs_dim, Model::obs_dim, P>& precision,
    const Vec<particle_draw_dim<Model, false>>& z, double u, double log_weight, double log_normalizer,
    const Vec<Model::obs_dim, P>& vinv_dy, const typename Model::Control& control, Vec<Model::state_dim, S>& xs) {
  static_assert(std::is_same_v<S, particle_step_scalar<Model, Real>>, "the step's scalar");
  static_assert(std::is_same_v<P, double> || std::is_same_v<P, S>, "V^-1 in double or in the step's scalar");
  if constexpr (has_exact_transition<Model>::value) {
    xs = d.model.sample_exact_transition(t, xs, d.dt, z, u);
  } else {
    xs = euler_maruyama_step<FloatIncrements>(d, t, xs, z, control);
  }
  const Vec<Model::obs_dim, S> h = d.model.observation(t + d.dt, xs);
  const S increment = dot(h, convert<S>(vinv_dy)) - d.template half_dt_as<S>() * dot(h, convert<S>(precision) * h);
  // In S, the normalizer rounded alone: it is the member's, so its rounding moves all of the member's log-weights
  // alike, which the normalization takes back; a float step spends no conversions on the subtraction.
  return static_cast<S>(log_weight) - static_cast<S>(log_normalizer) + increment;
}

/// update_particle before its results are rounded to the bank's storage.
template <bool Initialize, bool FloatIncrements, class Model, class MemSpace, class Real, class P>
KOKKOS_INLINE_FUNCTION double update_particle_unrounded(
    const ParticleStepData<Model, MemSpace, Real>& d, double t, const Mat<Model::obs_dim, Model::obs_dim, P>& precision,
    const Vec<particle_draw_dim<Model, Initialize>>& z, double u, double log_weight, double log_normalizer,
    const Vec<Model::obs_dim, P>& vinv_dy, const typename Model::Control& control, Vec<Model::state_dim>& x) {
  constexpr int n = Model::state_dim;
  if constexpr (Initialize) {
    x = d.initial_mean + d.initial_root * z;
    return 0.0;
  } else if constexpr (Model::discrete_time) {
    x = d.model.transition(t, x, control) + d.model.process_noise(z, u);
    return finite_or_dead(
        log_weight - log_normalizer + d.model.observation_log_density(vinv_dy - d.model.observation(t + 1.0, x)), x);
  } else {
    // In S: float where fp32 stores floats and the model's dynamics take float (particle_step_scalar), else double
    // (every convert<double> below is then a copy, and the expressions are those of the double step).
    using S = particle_step_scalar<Model, Real>;
    Vec<n, S> xs = convert<S>(x);
    const double l =
        continuous_time_step<FloatIncrements>(d, t, precision, z, u, log_weight, log_normalizer, vinv_dy, control, xs);
    x = convert<double>(xs);
    return finite_or_dead(l, x);
  }
}
}  // namespace detail

/// Moves one particle (x in, x out) over [t, t + dt] with its draws (normals z, uniform u) and returns its new
/// log-weight, normalized by the member's previous log-normalizer; -inf for a particle that left the finite
/// numbers. `precision` is V^{-1} at t; `control` is the member's (particle_control). A discrete-time model's
/// precision is the identity, so `vinv_dy` is z[k+1] itself. The step computes in particle_step_scalar (float only
/// for fp32 and a model with float dynamics): `precision` and `vinv_dy` in double, or already rounded to that
/// scalar (the GPU's kernels, once per member, not per particle); x and the log-weight come out as the bank stores
/// them (stored_value). With FloatIncrements (`mixed`'s kernels: ParticleStepData::float_increments) the
/// Euler-Maruyama increment is computed in float (euler_maruyama_step).
template <bool Initialize, bool FloatIncrements = false, class Model, class MemSpace, class Real, class P>
KOKKOS_INLINE_FUNCTION double update_particle(const ParticleStepData<Model, MemSpace, Real>& d, double t,
                                              const Mat<Model::obs_dim, Model::obs_dim, P>& precision,
                                              const Vec<particle_draw_dim<Model, Initialize>>& z, double u,
                                              double log_weight, double log_normalizer,
                                              const Vec<Model::obs_dim, P>& vinv_dy,
                                              const typename Model::Control& control, Vec<Model::state_dim>& x) {
  const double l = detail::update_particle_unrounded<Initialize, FloatIncrements>(d, t, precision, z, u, log_weight,
                                                                                  log_normalizer, vinv_dy, control, x);
  return round_to_storage<Real>(x, l);
}

/// update_particle of a particle held in float between a kernel's steps, for a step that computes in float (fp32 and
/// a model with float dynamics: the GPU's team kernels hold such particles in float from load to store): the same x
/// and log-weight, without a float's trip through double and back at every step (a GPU converts between them at a
/// fraction of its float rate) and with the finite checks on the floats. A particle's first step (Initialize) is
/// update_particle's.
template <bool Initialize, bool FloatIncrements = false, class Model, class MemSpace, class P>
KOKKOS_INLINE_FUNCTION float update_particle(const ParticleStepData<Model, MemSpace, float>& d, double t,
                                             const Mat<Model::obs_dim, Model::obs_dim, P>& precision,
                                             const Vec<particle_draw_dim<Model, Initialize>>& z, double u,
                                             float log_weight, double log_normalizer,
                                             const Vec<Model::obs_dim, P>& vinv_dy,
                                             const typename Model::Control& control, Vec<Model::state_dim, float>& x) {
  static_assert(std::is_same_v<particle_step_scalar<Model, float>, float>, "a step computed in float");
  if constexpr (Initialize) {
    Vec<Model::state_dim> xd = convert<double>(x);
    const double l = update_particle<true>(d, t, precision, z, u, log_weight, log_normalizer, vinv_dy, control, xd);
    x = convert<float>(xd);
    return static_cast<float>(l);
  } else {
    return finite_or_dead(detail::continuous_time_step<FloatIncrements>(d, t, precision, z, u, log_weight,
                                                                        log_normalizer, vinv_dy, control, x),
                          x);
  }
}

/// The largest log-likelihood increment any particle can get from an increment dy: h.a - (dt/2) h^T V^-1 h
/// with a = V^-1 dy is largest at h = V a / dt, where it is dy^T V^-1 dy / (2 dt). The previous log-weights
/// are normalized (each <= 0), so this bounds every new log-weight from above; 0 where it is not finite.
/// A discrete-time model's bound is the largest log density of v.
template <class Model, int P>
KOKKOS_INLINE_FUNCTION double log_weight_bound(const Model& model, const Vec<P>& dy, const Vec<P>& vinv_dy, double dt) {
  double bound;
  if constexpr (Model::discrete_time)
    bound = model.observation_max_log_density();
  else
    bound = 0.5 * dot(dy, vinv_dy) / dt;
  return math::is_finite(bound) ? bound : 0.0;
}

}  // namespace kushner
