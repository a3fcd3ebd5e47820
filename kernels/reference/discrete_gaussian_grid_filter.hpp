#pragma once
// The exact Bayes filter of a discrete-time model with Gaussian noises, state dimension 1 or 2, on a grid that
// follows the posterior: the point-mass filter (Bucy & Senne 1971), the Gaussian twin of
// kernels/reference/discrete_grid_filter.hpp (Clark's bounded noises, whose kinks need exact cell masses). The
// posterior is a weight at each of G points per axis (uniform spacing h); step k:
//   1. the new grid: per axis, the images F(k, x_i, 0) of the points with weight widened by grid_kernel_cut
//      standard deviations of w on that axis (w's density beyond is below e^-32 of its peak);
//   2. predict: point i's weight spread over the new points with w's density, the product of one Gaussian per
//      axis (Cov w diagonal: axis-aligned noise), normalized over the points it reaches;
//   3. Bayes: times the likelihood N(z[k+1] - h(k+1, x_j); 0, V) (log densities, scaled by their largest: no
//      underflow however sharp z is), normalize; points left with less than 1e-16 of the weight hold nothing
//      from then on, so the next box is the image of the posterior's bulk, not of its far tails.
// Each step is the midpoint (trapezoidal) rule on a uniform grid for the Chapman-Kolmogorov and Bayes integrals,
// whose integrands here are smooth and decay like Gaussians: its error falls faster than any power of h once h
// is below the narrowest of w's and the posterior's standard deviations (tests: G against 2G points per axis, and
// the linear models' Kalman filter). Moments are the weighted points' (no cell-width correction: the rule is not
// a histogram). One member per work item, O(G^(2D)) per step at most (the kernel's reach cuts it): a reference.
#include "core/errors.hpp"
#include "core/linear_algebra.hpp"
#include "core/math.hpp"
#include "core/status.hpp"
#include "kernels/bank.hpp"
#include "kernels/for_each_member.hpp"
#include "kernels/reference/grid_filter.hpp"

#include <Kokkos_Core.hpp>

#include <cmath>
#include <vector>

namespace kushner {

template <class Model, class MemSpace>
struct DiscreteGaussianGridStep {
  static constexpr int D = Model::state_dim;
  /// Posterior weight below this fraction leaves the grid (at most cells * 1e-16 of the mass in all).
  static constexpr double dropped_mass = 1e-16;
  Model model;
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> mass, next;  // (point, member); point = i0 G + i1
  BankVector<MemSpace> lower, width;  // (member, axis): the points lower + (i + 1/2) width
  BankVector<MemSpace> z, mean;
  BankSymmetric<MemSpace> covariance;
  BankScalar<Status, MemSpace> status;
  int axis_cells;
  double k;

  KOKKOS_INLINE_FUNCTION int cells() const { return D == 1 ? axis_cells : axis_cells * axis_cells; }
  /// Centre of cell c of the grid (lo, h) with `per_axis` cells per axis.
  KOKKOS_INLINE_FUNCTION static Vec<D> cell_centre(int c, int per_axis, const Vec<D>& lo, const Vec<D>& h) {
    Vec<D> x;
    x[0] = lo[0] + ((D == 1 ? c : c / per_axis) + 0.5) * h[0];
    if constexpr (D == 2) x[1] = lo[1] + (c % per_axis + 0.5) * h[1];
    return x;
  }
  KOKKOS_INLINE_FUNCTION Vec<D> centre(int c, const Vec<D>& lo, const Vec<D>& h) const {
    return cell_centre(c, axis_cells, lo, h);
  }
  /// The new points first .. last (clipped) of one axis that w's kernel around y reaches.
  KOKKOS_INLINE_FUNCTION void reach(double y, double s, double lo, double h, long& first, long& last) const {
    first = floor_to_long((y - grid_kernel_cut * s - lo) / h);
    last = floor_to_long((y + grid_kernel_cut * s - lo) / h);
    first = first < 0 ? 0 : first;
    last = last > axis_cells - 1 ? axis_cells - 1 : last;
  }
  /// w's density (up to a constant) at point j of one axis, from y with standard deviation s.
  KOKKOS_INLINE_FUNCTION static double kernel(double y, double s, double lo, double h, long j) {
    const double r = (lo + (j + 0.5) * h - y) / s;
    return math::exp(-0.5 * r * r);
  }
  /// The sum of kernel() over first .. last; out[j - first] the values when out is given. A kernel far narrower
  /// than the points' spacing underflows everywhere: its mass then goes to the nearest point.
  KOKKOS_INLINE_FUNCTION double spread(double y, double s, double lo, double h, long& first, long& last,
                                       double* out) const {
    double sum = 0.0;
    for (long j = first; j <= last; ++j) {
      const double v = kernel(y, s, lo, h, j);
      if (out != nullptr) out[j - first] = v;
      sum += v;
    }
    if (sum > 0.0) return sum;
    const long nearest = floor_to_long((y - lo) / h);
    first = last = nearest < 0 ? 0 : (nearest > axis_cells - 1 ? axis_cells - 1 : nearest);
    if (out != nullptr) out[0] = 1.0;
    return -1.0;  // the nearest point alone (first = last), weight 1
  }

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    if (status(member) != Status::ok) return;
    const typename Model::Control u = Model::Control::zero();
    const int n_cells = cells();
    Vec<D> lo, h, s, new_lo, new_h;
    const Mat<D, D> Q = model.process_noise_covariance(k);
    for (int a = 0; a < D; ++a) {
      lo[a] = lower(member, a);
      h[a] = width(member, a);
      s[a] = math::sqrt(Q(a, a));
    }
    // 1. The new grid.
    // Set by the first occupied cell; where no cell is, the grid is unusable below and these zeros are not used.
    Vec<D> f_min = Vec<D>::constant(0.0), f_max = f_min;
    bool occupied = false;
    for (int c = 0; c < n_cells; ++c) {
      if (!(mass(c, member) > 0.0)) continue;
      const Vec<D> y = model.transition(k, centre(c, lo, h), u);
      for (int a = 0; a < D; ++a) {
        f_min[a] = occupied && f_min[a] < y[a] ? f_min[a] : y[a];
        f_max[a] = occupied && f_max[a] > y[a] ? f_max[a] : y[a];
      }
      occupied = true;
    }
    bool usable = occupied;
    for (int a = 0; a < D; ++a) {
      new_lo[a] = f_min[a] - grid_kernel_cut * s[a];
      new_h[a] = (f_max[a] - f_min[a] + 2.0 * grid_kernel_cut * s[a]) / axis_cells;
      usable = usable && new_h[a] > 0.0 && math::is_finite(new_lo[a]) && math::is_finite(new_h[a]);
    }
    if (!usable) {
      status(member) = Status::non_finite;  // no mass left, or the transition left the numbers
      return;
    }
    // 2. Predict: each point's mass spread over the new points with w's density, axis by axis (normalized over
    // the points it reaches, so no mass is lost to the lattice).
    for (int c = 0; c < n_cells; ++c) next(c, member) = 0.0;
    for (int c = 0; c < n_cells; ++c) {
      const double p = mass(c, member);
      if (!(p > 0.0)) continue;
      const Vec<D> y = model.transition(k, centre(c, lo, h), u);
      long first0, last0;
      reach(y[0], s[0], new_lo[0], new_h[0], first0, last0);
      if constexpr (D == 1) {  // up to all the points of the axis: the kernel twice, not an array
        const double sum = spread(y[0], s[0], new_lo[0], new_h[0], first0, last0, nullptr);
        for (long j = first0; j <= last0; ++j)
          next(j, member) += sum > 0.0 ? (p / sum) * kernel(y[0], s[0], new_lo[0], new_h[0], j) : p;
      } else {  // axis_cells <= grid_max_band
        long first1, last1;
        reach(y[1], s[1], new_lo[1], new_h[1], first1, last1);
        double spread0[grid_max_band], spread1[grid_max_band];
        const double scale = p / (math::fabs(spread(y[0], s[0], new_lo[0], new_h[0], first0, last0, spread0)) *
                                  math::fabs(spread(y[1], s[1], new_lo[1], new_h[1], first1, last1, spread1)));
        for (long i = first0; i <= last0; ++i) {
          const double p0 = scale * spread0[i - first0];
          for (long j = first1; j <= last1; ++j) next(i * axis_cells + j, member) += p0 * spread1[j - first1];
        }
      }
    }
    // 3. Bayes: the log-likelihoods (kept in `mass`, which the prediction has read), then the scaled product.
    Vec<D> zk;
    for (int i = 0; i < D; ++i) zk[i] = z(member, i);
    double largest = -math::infinity();
    for (int c = 0; c < n_cells; ++c) {
      if (!(next(c, member) > 0.0)) continue;
      const double l = model.observation_log_density(zk - model.observation(k + 1.0, centre(c, new_lo, new_h)));
      mass(c, member) = l;
      largest = l > largest ? l : largest;
    }
    double total = 0.0;
    Vec<D> first_moment = Vec<D>::zero();
    for (int c = 0; c < n_cells; ++c) {
      const double q = next(c, member) > 0.0 ? next(c, member) * math::exp(mass(c, member) - largest) : 0.0;
      next(c, member) = q;
      total += q;
      first_moment += q * centre(c, new_lo, new_h);
    }
    if (!(total > 0.0) || !math::is_finite(total)) {
      status(member) = Status::non_finite;  // z[k+1] beyond every cell's likelihood
      return;
    }
    const Vec<D> m = (1.0 / total) * first_moment;
    Mat<D, D> second = Mat<D, D>::zero();
    for (int c = 0; c < n_cells; ++c) {
      const double q = next(c, member) / total;
      const Vec<D> d = centre(c, new_lo, new_h) - m;
      for (int i = 0; i < D; ++i)
        for (int j = i; j < D; ++j) second(i, j) += q * d[i] * d[j];
      mass(c, member) = q >= dropped_mass ? q : 0.0;
    }
    for (int i = 0; i < D; ++i) {
      lower(member, i) = new_lo[i];
      width(member, i) = new_h[i];
      mean(member, i) = m[i];
      for (int j = i; j < D; ++j) covariance(member, packed_index(D, i, j)) = second(i, j);
    }
  }
};

/// Grid reference for discrete-time models with Gaussian noises of state dimension 1 or 2: posterior mean
/// (member, i) and covariance (member, packed) of every member of a bank, from the filters' prior N(prior_mean,
/// prior_cov) (a point when prior_cov = 0).
template <class ExecSpace, class Model>
class DiscreteGaussianGridFilter {
 public:
  using MemSpace = typename ExecSpace::memory_space;
  static constexpr int D = Model::state_dim;
  static_assert(Model::discrete_time && (D == 1 || D == 2),
                "DiscreteGaussianGridFilter: discrete-time models of dimension 1 or 2");
  /// 64 per axis in 2-D: the Duffing example (models/examples/duffing_discrete.toml) is within 2e-4 of 128
  /// points at 64 against 0.012 at 40 (rms over 40 members after 30 steps; a particle filter of 2^18 particles
  /// agrees to its own 0.004).
  static constexpr int default_axis_cells = D == 1 ? 400 : 64;
  /// Bytes allocated per member: the masses (two copies), the grid, the posterior.
  static double bytes_per_member(int axis_cells = default_axis_cells) {
    const double cells = D == 1 ? axis_cells : static_cast<double>(axis_cells) * axis_cells;
    return sizeof(double) * (2.0 * cells + 3 * D + packed_size(D)) + sizeof(Status);
  }

  /// Why the grid cannot run `model` (nullptr: it can): it needs Cov w diagonal with a positive diagonal, and a
  /// prior covariance positive definite or zero.
  static const char* unsupported(const Model& model) {
    const Mat<D, D> Q = model.process_noise_covariance(0.0);
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j) {
        if (i != j && Q(i, j) != 0.0)
          return "the discrete grid filter needs axis-aligned process noise (G G^T diagonal)";
        if (i == j && !(Q(i, i) > 0.0)) return "the discrete grid filter needs process noise on every state";
      }
    Mat<D, D> L;
    bool zero = true;
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j) zero = zero && model.prior_cov(i, j) == 0.0;
    if (!zero && !cholesky(model.prior_cov, L))
      return "the discrete grid filter needs a prior covariance that is positive definite or zero";
    return nullptr;
  }

  DiscreteGaussianGridFilter(const ExecSpace& space, const Model& model, int num_members,
                             int axis_cells = default_axis_cells)
      : space_(space), model_(model), axis_cells_(axis_cells) {
    KUSHNER_INPUT_REQUIRE(axis_cells >= 8 && (D == 1 || axis_cells <= grid_max_band),
                          "grid: 8 to " << grid_max_band << " cells per axis (got " << axis_cells << ")");
    const char* why = unsupported(model);
    KUSHNER_INPUT_REQUIRE(why == nullptr, Model::name << ": " << why);
    const int cells = D == 1 ? axis_cells : axis_cells * axis_cells;
    mass_ = decltype(mass_)("kushner::discrete_gaussian_grid_mass", cells, num_members);
    next_ = decltype(next_)("kushner::discrete_gaussian_grid_next", cells, num_members);
    lower_ = BankVector<MemSpace>("kushner::discrete_gaussian_grid_lower", num_members, D);
    width_ = BankVector<MemSpace>("kushner::discrete_gaussian_grid_width", num_members, D);
    mean_ = BankVector<MemSpace>("kushner::discrete_gaussian_grid_mean", num_members, D);
    covariance_ = BankSymmetric<MemSpace>("kushner::discrete_gaussian_grid_covariance", num_members, packed_size(D));
    status_ = BankScalar<Status, MemSpace>("kushner::discrete_gaussian_grid_status", num_members);
    // The prior on the box m0 -+ grid_kernel_cut standard deviations per axis: N(m0, P0) at the points,
    // normalized; a point prior is one point (spacing 0) at m0. The same for every member.
    const Vec<D> m0 = model.prior_mean;
    const Mat<D, D> P0 = model.prior_cov;
    Mat<D, D> L;
    const bool point = !cholesky(P0, L);
    Vec<D> lo, h;
    for (int a = 0; a < D; ++a) {
      const double sd = point ? 0.0 : std::sqrt(P0(a, a));
      lo[a] = m0[a] - grid_kernel_cut * sd;
      h[a] = 2.0 * grid_kernel_cut * sd / axis_cells;
    }
    std::vector<double> prior(cells, 0.0);
    if (point) {
      prior[0] = 1.0;
    } else {
      using Step = DiscreteGaussianGridStep<Model, MemSpace>;
      double total = 0.0;
      for (int c = 0; c < cells; ++c)
        total += prior[c] = std::exp(-0.5 * cholesky_quadratic_form(L, Step::cell_centre(c, axis_cells, lo, h) - m0));
      for (double& p : prior) p = p / total >= Step::dropped_mass ? p / total : 0.0;
    }
    auto mass = Kokkos::create_mirror_view(mass_);
    auto lower = Kokkos::create_mirror_view(lower_);
    auto width = Kokkos::create_mirror_view(width_);
    auto mean = Kokkos::create_mirror_view(mean_);
    auto cov = Kokkos::create_mirror_view(covariance_);
    for (int member = 0; member < num_members; ++member) {
      for (int c = 0; c < cells; ++c) mass(c, member) = prior[c];
      for (int i = 0; i < D; ++i) {
        lower(member, i) = lo[i];
        width(member, i) = h[i];
        mean(member, i) = m0[i];
        for (int j = i; j < D; ++j) cov(member, packed_index(D, i, j)) = P0(i, j);
      }
    }
    Kokkos::deep_copy(space_, mass_, mass);
    Kokkos::deep_copy(space_, lower_, lower);
    Kokkos::deep_copy(space_, width_, width);
    Kokkos::deep_copy(space_, mean_, mean);
    Kokkos::deep_copy(space_, covariance_, cov);
    space_.fence();  // the host mirrors go out of scope
  }

  /// Step k -> k + 1 with z[k+1] (member, i).
  void step(long k, double, const BankVector<MemSpace>& z) {
    KUSHNER_REQUIRE(z.extent(0) == mean_.extent(0) && z.extent_int(1) == Model::obs_dim, "z has the wrong shape");
    parallel_for_members(
        "kushner::discrete_gaussian_grid_step", space_, mean_.extent(0),
        DiscreteGaussianGridStep<Model, MemSpace>{model_, mass_, next_, lower_, width_, z, mean_, covariance_, status_,
                                                  axis_cells_, static_cast<double>(k)});
  }

  const BankVector<MemSpace>& posterior_mean() const { return mean_; }
  const BankSymmetric<MemSpace>& posterior_covariance() const { return covariance_; }
  const BankScalar<Status, MemSpace>& status() const { return status_; }
  int cells() const { return D == 1 ? axis_cells_ : axis_cells_ * axis_cells_; }

  /// What a checkpoint holds (engine/state_archive.hpp).
  template <class Archive>
  void visit_state(Archive& archive) {
    archive.view("mass", mass_);
    archive.view("lower", lower_);
    archive.view("width", width_);
    archive.view("mean", mean_);
    archive.view("covariance", covariance_);
    archive.view("status", status_);
  }

 private:
  ExecSpace space_;
  Model model_;
  int axis_cells_;
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> mass_, next_;
  BankVector<MemSpace> lower_, width_;
  BankVector<MemSpace> mean_;
  BankSymmetric<MemSpace> covariance_;
  BankScalar<Status, MemSpace> status_;
};

}  // namespace kushner
