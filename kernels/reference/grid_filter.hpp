#pragma once
// Grid (point-mass) filter for state dimension 1 and 2: the filtering density as masses on a regular grid
// that follows the posterior (Bucy & Senne 1971; Simandl, Kralovec & Soderstrom 2006, "Advanced point-mass
// method for nonlinear state estimation", Automatica 42). One observation step:
//   1. place the new grid at the predicted mean +- K predicted standard deviations per axis;
//   2. predict (Chapman-Kolmogorov / discrete Fokker-Planck): the mass of every node moves to the Euler-
//      Maruyama mean mu = x + f(x) dt and spreads with N(mu, G G^T dt) over the new nodes. An axis with noise
//      gets the Gaussian sampled at the nodes, normalized over the unclipped lattice (mass that leaves the
//      grid is lost, not pushed inward); an axis without noise (the cubic oscillator's x1) gets the
//      transpose of 4-point Lagrange interpolation, which keeps moments 0..3 exactly and so adds no numerical
//      diffusion;
//   3. Bayes: multiply by the likelihood exp(h^T V^{-1} dy - dt/2 h^T V^{-1} h) at the nodes, normalize.
// It targets the same discrete model as the particle filter (Euler-Maruyama transition, likelihood at the
// propagated state), so the two differ by Monte Carlo and quadrature error only. The Gaussian kernel is
// resolved while its width is about a grid spacing or more (aliasing error ~ exp(-2 pi^2 sigma^2 / h^2)):
// min_resolution() reports the smallest sigma / h met. Axis-aligned noise only (G G^T diagonal).
// One member per work item, sequential over the grid: a reference, not a fast path.
#include "core/eigen_helpers.hpp"
#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "core/math.hpp"
#include "core/status.hpp"
#include "kernels/bank.hpp"
#include "kernels/for_each_member.hpp"
#include "models/model_traits.hpp"

#include <Kokkos_Core.hpp>

#include <cmath>
#include <vector>

namespace kushner {

struct GridOptions {
  int points_per_axis = 0;  // 0: 256 in 1-D, 128 in 2-D
  double half_width = 0.0;  // grid half-width in predicted standard deviations; 0: 8 in 1-D, 7 in 2-D
  bool truth_law = false;   // start from the truths' law instead of the filters' prior
};

/// Largest number of nodes one node's mass spreads over per axis (kernels up to sigma / h = 15 at the cut
/// below; wider ones are cut shorter). Two of these live in each work item's local memory, which a GPU
/// reserves for every resident thread: keep them small.
constexpr int grid_max_band = 256;
/// Gaussian kernels are cut at this many standard deviations (e^{-32} = 1.3e-14 of the peak).
constexpr double grid_kernel_cut = 8.0;

/// Weights of one node's mass over the nodes of one axis: nodes first .. first + count - 1.
struct AxisSpread {
  int first = 0, count = 0;
  double weight[grid_max_band];
};

KOKKOS_INLINE_FUNCTION long floor_to_long(double v) {
  const long k = static_cast<long>(v);
  return static_cast<double>(k) > v ? k - 1 : k;
}

/// Mass at position s (in node units of the new axis, 0 .. n-1) spread with standard deviation sigma (node
/// units): Gaussian samples normalized over the unclipped lattice, or cubic Lagrange weights when sigma = 0.
KOKKOS_INLINE_FUNCTION void spread_on_axis(double s, double sigma, int n, AxisSpread& out) {
  out.first = 0;
  out.count = 0;
  if (!math::is_finite(s) || s < -grid_max_band || s > n + grid_max_band) return;  // entirely off the grid
  if (!(sigma > 0.0)) {
    const long i0 = floor_to_long(s) - 1;
    const double tau = s - static_cast<double>(i0);  // in [1, 2)
    const double w[4] = {-(tau - 1.0) * (tau - 2.0) * (tau - 3.0) / 6.0, tau * (tau - 2.0) * (tau - 3.0) / 2.0,
                         -tau * (tau - 1.0) * (tau - 3.0) / 2.0, tau * (tau - 1.0) * (tau - 2.0) / 6.0};
    for (long i = i0; i < i0 + 4; ++i) {
      if (i < 0 || i >= n) continue;
      if (out.count == 0) out.first = static_cast<int>(i);
      out.weight[out.count++] = w[i - i0];
    }
    return;
  }
  double reach = grid_kernel_cut * sigma;
  if (2.0 * reach + 4.0 > grid_max_band) reach = 0.5 * (grid_max_band - 4);
  const long lo = floor_to_long(s - reach), hi = floor_to_long(s + reach) + 1;
  double total = 0.0;
  for (long i = lo; i <= hi; ++i) {
    const double d = (static_cast<double>(i) - s) / sigma;
    const double w = math::exp(-0.5 * d * d);
    total += w;
    if (i < 0 || i >= n) continue;
    if (out.count == 0) out.first = static_cast<int>(i);
    out.weight[out.count++] = w;
  }
  for (int k = 0; k < out.count; ++k) out.weight[k] /= total;
}

template <class Model, class MemSpace>
struct GridFilterStep {
  static constexpr int D = Model::state_dim, p = Model::obs_dim;
  Model model;
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> mass, next;  // (cell, member); cell = a + n b
  BankVector<MemSpace> center, spacing;                             // (member, d)
  BankVector<MemSpace> dy, mean;
  BankSymmetric<MemSpace> covariance;
  BankScalar<double, MemSpace> resolution;  // smallest sigma / h so far
  BankScalar<Status, MemSpace> status;
  Mat<p, p> observation_precision;
  int n;
  double half_width, t, dt;

  KOKKOS_INLINE_FUNCTION int cells() const { return D == 1 ? n : n * n; }
  KOKKOS_INLINE_FUNCTION Vec<D> node(int cell, const Vec<D>& c, const Vec<D>& h) const {
    Vec<D> x;
    x[0] = c[0] + h[0] * ((cell % n) - 0.5 * (n - 1));
    if constexpr (D == 2) x[1] = c[1] + h[1] * ((cell / n) - 0.5 * (n - 1));
    return x;
  }

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    if (status(member) != Status::ok) return;
    const typename Model::Control u = Model::Control::zero();
    const Vec<D> c = load<D>(center, member), h = load<D>(spacing, member);
    // 1. Predicted moments place the new grid.
    double s0 = 0.0;
    Vec<D> s1 = Vec<D>::zero();
    Mat<D, D> s2 = Mat<D, D>::zero();
    for (int cell = 0; cell < cells(); ++cell) {
      const double w = mass(cell, member);
      if (w == 0.0) continue;
      const Vec<D> x = node(cell, c, h);
      const Vec<D> mu = x + model.drift(t, x, u) * dt;
      const auto g = model.diffusion(t, x);
      const Mat<D, D> q = g * transpose(g) * dt;
      s0 += w;
      s1 += mu * w;
      s2 += (outer(mu, mu) + q) * w;
    }
    const Vec<D> predicted_mean = s1 * (1.0 / s0);
    Vec<D> c_new, h_new;
    for (int d = 0; d < D; ++d) {
      const double var = s2(d, d) / s0 - predicted_mean[d] * predicted_mean[d];
      c_new[d] = predicted_mean[d];
      h_new[d] = var > 0.0 ? 2.0 * half_width * math::sqrt(var) / n : h[d];
    }
    // 2. Prediction: spread every node's mass over the new grid.
    for (int cell = 0; cell < cells(); ++cell) next(cell, member) = 0.0;
    double worst = resolution(member);
    AxisSpread a0, a1;
    for (int cell = 0; cell < cells(); ++cell) {
      const double w = mass(cell, member);
      if (w == 0.0) continue;
      const Vec<D> x = node(cell, c, h);
      const Vec<D> mu = x + model.drift(t, x, u) * dt;
      const auto g = model.diffusion(t, x);
      const Mat<D, D> q = g * transpose(g) * dt;
      Vec<D> s, sigma;
      for (int d = 0; d < D; ++d) {
        s[d] = (mu[d] - c_new[d]) / h_new[d] + 0.5 * (n - 1);
        sigma[d] = math::sqrt(q(d, d)) / h_new[d];
        if (sigma[d] > 0.0 && sigma[d] < worst) worst = sigma[d];
      }
      spread_on_axis(s[0], sigma[0], n, a0);
      if constexpr (D == 1) {
        for (int k = 0; k < a0.count; ++k) next(a0.first + k, member) += w * a0.weight[k];
      } else {
        spread_on_axis(s[1], sigma[1], n, a1);
        for (int k1 = 0; k1 < a1.count; ++k1) {
          const double w1 = w * a1.weight[k1];
          const int row = (a1.first + k1) * n;
          for (int k0 = 0; k0 < a0.count; ++k0) next(row + a0.first + k0, member) += w1 * a0.weight[k0];
        }
      }
    }
    resolution(member) = worst;
    // 3. Bayes update at the new nodes, then moments.
    const Vec<p> vinv_dy = observation_precision * load<p>(dy, member);
    double top = -1e300;
    for (int cell = 0; cell < cells(); ++cell) {
      if (next(cell, member) == 0.0) continue;
      const Vec<p> hx = model.observation(t + dt, node(cell, c_new, h_new));
      const double l = dot(hx, vinv_dy) - 0.5 * dt * dot(hx, observation_precision * hx);
      top = l > top ? l : top;
    }
    double total = 0.0;
    Vec<D> first = Vec<D>::zero();
    for (int cell = 0; cell < cells(); ++cell) {
      double w = next(cell, member);
      if (w != 0.0) {
        const Vec<D> x = node(cell, c_new, h_new);
        const Vec<p> hx = model.observation(t + dt, x);
        w *= math::exp(dot(hx, vinv_dy) - 0.5 * dt * dot(hx, observation_precision * hx) - top);
        total += w;
        first += x * w;
      }
      mass(cell, member) = w;
    }
    if (!(total > 0.0) || !math::is_finite(total)) {
      status(member) = Status::non_finite;
      return;
    }
    const Vec<D> m = first * (1.0 / total);
    Mat<D, D> cov = Mat<D, D>::zero();
    for (int cell = 0; cell < cells(); ++cell) {
      const double w = mass(cell, member) / total;
      mass(cell, member) = w;
      if (w == 0.0) continue;
      const Vec<D> dx = node(cell, c_new, h_new) - m;
      cov += outer(dx, dx) * w;
    }
    store(center, member, c_new);
    store(spacing, member, h_new);
    store(mean, member, m);
    store_symmetric(covariance, member, cov);
  }
};

/// Grid reference for 1-D and 2-D continuous-time models: posterior mean (member, i) and covariance
/// (member, packed) of every member of a bank.
template <class ExecSpace, class Model>
class GridFilter {
 public:
  using MemSpace = typename ExecSpace::memory_space;
  static constexpr int D = Model::state_dim;
  static_assert(D == 1 || D == 2, "GridFilter: state dimension 1 or 2");
  static_assert(!Model::discrete_time, "GridFilter: continuous-time models only");

  static int points_per_axis(const GridOptions& options) {
    return options.points_per_axis > 0 ? options.points_per_axis : (D == 1 ? 256 : 128);
  }
  /// Why it cannot run `model` (kernels/reference/exact_reference.hpp): a model file whose noise is not
  /// axis-aligned (a built-in model's is, or it has no grid filter); the constructor checks b b^T at the mean.
  static const char* unsupported(const Model& model) {
    if constexpr (ModelTraits<Model>::runtime_checked)
      if (!model.model_facts().axis_aligned_noise) return "the grid filter needs axis-aligned noise (b b^T diagonal)";
    return nullptr;
  }
  /// Bytes allocated per member: the masses (two copies) and the grid's and posterior's numbers.
  static double bytes_per_member(const GridOptions& options = {}) {
    const double cells =
        D == 1 ? points_per_axis(options) : static_cast<double>(points_per_axis(options)) * points_per_axis(options);
    return sizeof(double) * (2.0 * cells + 3 * D + packed_size(D) + 1) + sizeof(Status);
  }

  GridFilter(const ExecSpace& space, const Model& model, int num_members, GridOptions options = {})
      : space_(space), model_(model) {
    n_ = points_per_axis(options);
    half_width_ = options.half_width > 0.0 ? options.half_width : (D == 1 ? 8.0 : 7.0);
    KUSHNER_INPUT_REQUIRE(n_ >= 8, "grid: points_per_axis must be at least 8 (got " << n_ << ")");
    const Vec<D> m0 = options.truth_law ? model.x0_mean : model.prior_mean;
    const Mat<D, D> P0 = options.truth_law ? model.x0_cov : model.prior_cov;
    check_covariance("grid initial covariance", P0, /*allow_singular=*/false);
    const auto g = model.diffusion(0.0, m0);
    const Mat<D, D> q = g * transpose(g);
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j)
        KUSHNER_INPUT_REQUIRE(i == j || q(i, j) == 0.0,
                              Model::name << ": the grid filter needs axis-aligned noise (G G^T diagonal)");
    const int cells = D == 1 ? n_ : n_ * n_;
    mass_ = decltype(mass_)("kushner::grid_mass", cells, num_members);
    next_ = decltype(next_)("kushner::grid_next", cells, num_members);
    center_ = BankVector<MemSpace>("kushner::grid_center", num_members, D);
    spacing_ = BankVector<MemSpace>("kushner::grid_spacing", num_members, D);
    mean_ = BankVector<MemSpace>("kushner::grid_mean", num_members, D);
    covariance_ = BankSymmetric<MemSpace>("kushner::grid_covariance", num_members, packed_size(D));
    resolution_ = BankScalar<double, MemSpace>("kushner::grid_resolution", num_members);
    status_ = BankScalar<Status, MemSpace>("kushner::grid_status", num_members);

    // Initial masses: the Gaussian density at the nodes of a grid at m0 +- K sd.
    Mat<D, D> L;
    KUSHNER_REQUIRE(cholesky(P0, L), "grid initial covariance not positive definite");
    auto mass = Kokkos::create_mirror_view(mass_);
    auto center = Kokkos::create_mirror_view(center_);
    auto spacing = Kokkos::create_mirror_view(spacing_);
    auto mean = Kokkos::create_mirror_view(mean_);
    auto cov = Kokkos::create_mirror_view(covariance_);
    auto resolution = Kokkos::create_mirror_view(resolution_);
    Vec<D> h;
    for (int d = 0; d < D; ++d) h[d] = 2.0 * half_width_ * std::sqrt(P0(d, d)) / n_;
    std::vector<double> w(cells);
    double total = 0.0;
    for (int cell = 0; cell < cells; ++cell) {
      Vec<D> dx;
      dx[0] = h[0] * ((cell % n_) - 0.5 * (n_ - 1));
      if constexpr (D == 2) dx[1] = h[1] * ((cell / n_) - 0.5 * (n_ - 1));
      w[cell] = std::exp(-0.5 * cholesky_quadratic_form(L, dx));
      total += w[cell];
    }
    for (int k = 0; k < num_members; ++k) {
      for (int cell = 0; cell < cells; ++cell) mass(cell, k) = w[cell] / total;
      store(center, k, m0);
      store(spacing, k, h);
      store(mean, k, m0);
      store_symmetric(cov, k, P0);
      resolution(k) = 1e300;
    }
    Kokkos::deep_copy(space_, mass_, mass);
    Kokkos::deep_copy(space_, center_, center);
    Kokkos::deep_copy(space_, spacing_, spacing);
    Kokkos::deep_copy(space_, mean_, mean);
    Kokkos::deep_copy(space_, covariance_, cov);
    Kokkos::deep_copy(space_, resolution_, resolution);
  }

  /// Step k: [k dt, (k + 1) dt] with increments dy (member, j).
  void step(long k, double dt, const BankVector<MemSpace>& dy) {
    constexpr int p = Model::obs_dim;
    KUSHNER_REQUIRE(dy.extent(0) == mean_.extent(0) && dy.extent_int(1) == p, "dy has the wrong shape");
    const double t = k * dt;
    const Mat<p, p> r = model_.observation_noise(t);
    Mat<p, p> root;
    KUSHNER_REQUIRE(cholesky(r * transpose(r), root), Model::name << ": R R^T not positive definite");
    parallel_for_members(
        "kushner::grid_filter_step", space_, mean_.extent(0),
        GridFilterStep<Model, MemSpace>{model_, mass_, next_, center_, spacing_, dy, mean_, covariance_, resolution_,
                                        status_, cholesky_inverse(root), n_, half_width_, t, dt});
  }

  const BankVector<MemSpace>& posterior_mean() const { return mean_; }
  const BankSymmetric<MemSpace>& posterior_covariance() const { return covariance_; }
  const BankScalar<Status, MemSpace>& status() const { return status_; }
  /// (member): smallest kernel width / grid spacing so far over the noisy axes (>= 1: well resolved).
  const BankScalar<double, MemSpace>& min_resolution() const { return resolution_; }
  int points_per_axis() const { return n_; }

  /// What a checkpoint holds (engine/state_archive.hpp).
  template <class Archive>
  void visit_state(Archive& archive) {
    archive.view("mass", mass_);
    archive.view("center", center_);
    archive.view("spacing", spacing_);
    archive.view("mean", mean_);
    archive.view("covariance", covariance_);
    archive.view("resolution", resolution_);
    archive.view("status", status_);
  }

 private:
  ExecSpace space_;
  Model model_;
  int n_ = 0;
  double half_width_ = 0.0;
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> mass_, next_;
  BankVector<MemSpace> center_, spacing_, mean_;
  BankSymmetric<MemSpace> covariance_;
  BankScalar<double, MemSpace> resolution_;
  BankScalar<Status, MemSpace> status_;
};

}  // namespace kushner
