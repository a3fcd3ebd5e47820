#pragma once
// The exact Bayes filter of a scalar discrete-time model with bounded noises (Clark's family), on a grid of
// cells that follows the posterior: the point-mass filter (Bucy & Senne 1971) with exact cell masses. Step k:
//   1. the new grid: G equal cells on the predicted support (the image of the occupied cells under F, widened
//      by w's bound) cut to the measurement window z[k+1] -+ v's bound, outside which the likelihood is zero;
//   2. predict: the mass p_i of old cell i, at its centre x_i, moves to F(k, x_i, 0) + w; new cell j = [a, b)
//      receives p_i (F_w(b - F(x_i)) - F_w(a - F(x_i))), w's exact CDF (no sampled density: Clark's rho = 10
//      law is zero at 0 and steep at its bounds);
//   3. Bayes: times the likelihood's exact cell average (F_v(z - a) - F_v(z - b)) / (b - a), normalize.
// Mean and variance treat each cell's mass as uniform on it (+ h^2/12). Its error is the grid's, O(h^2) in the
// moments, with h at most 2 (v's bound) / G (the grid lies inside the measurement window); tests compare G and 4G.
// One member per work item, O(G^2) per step: a reference.
#include "core/errors.hpp"
#include "core/math.hpp"
#include "core/status.hpp"
#include "kernels/bank.hpp"
#include "kernels/for_each_member.hpp"
#include "kernels/reference/grid_filter.hpp"

#include <Kokkos_Core.hpp>

namespace kushner {

template <class Model, class MemSpace>
struct DiscreteGridStep {
  Model model;
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> mass, next;  // (cell, member)
  BankScalar<double, MemSpace> lower, width;                        // (member): grid start and cell width
  BankVector<MemSpace> z, mean;
  BankSymmetric<MemSpace> covariance;
  BankScalar<Status, MemSpace> status;
  int cells;
  double k;

  KOKKOS_INLINE_FUNCTION void operator()(const int member) const {
    if (status(member) != Status::ok) return;
    const typename Model::Control u = Model::Control::zero();
    const double lo = lower(member), h = width(member), zk = z(member, 0);
    const double w_bound = model.w.bound, v_bound = model.v.bound;
    // 1. The new grid.
    double f_min = 0.0, f_max = 0.0;
    bool occupied = false;
    for (int i = 0; i < cells; ++i) {
      if (!(mass(i, member) > 0.0)) continue;
      const double f = model.transition(k, Vec<1>{{lo + (i + 0.5) * h}}, u)[0];
      f_min = occupied && f_min < f ? f_min : f;
      f_max = occupied && f_max > f ? f_max : f;
      occupied = true;
    }
    double new_lo = f_min - w_bound, new_hi = f_max + w_bound;
    new_lo = new_lo > zk - v_bound ? new_lo : zk - v_bound;
    new_hi = new_hi < zk + v_bound ? new_hi : zk + v_bound;
    if (!occupied || !(new_lo < new_hi) || !math::is_finite(new_lo) || !math::is_finite(new_hi)) {
      status(member) = Status::non_finite;  // z[k+1] impossible under the model (or no mass left)
      return;
    }
    const double new_h = (new_hi - new_lo) / cells;
    // 2. Predict with w's CDF over the new cells each old cell's image reaches.
    for (int j = 0; j < cells; ++j) next(j, member) = 0.0;
    for (int i = 0; i < cells; ++i) {
      const double p = mass(i, member);
      if (!(p > 0.0)) continue;
      const double y = model.transition(k, Vec<1>{{lo + (i + 0.5) * h}}, u)[0];
      long first = floor_to_long((y - w_bound - new_lo) / new_h), last = floor_to_long((y + w_bound - new_lo) / new_h);
      first = first < 0 ? 0 : first;
      last = last > cells - 1 ? cells - 1 : last;
      double below = model.process_noise_cdf(new_lo + first * new_h - y);
      for (long j = first; j <= last; ++j) {
        const double upto = model.process_noise_cdf(new_lo + (j + 1) * new_h - y);
        next(j, member) += p * (upto - below);
        below = upto;
      }
    }
    // 3. Bayes with the likelihood's cell averages; moments.
    double total = 0.0, first_moment = 0.0;
    for (int j = 0; j < cells; ++j) {
      const double a = new_lo + j * new_h;
      const double likelihood =
          (model.observation_noise_cdf(zk - a) - model.observation_noise_cdf(zk - a - new_h)) / new_h;
      const double q = next(j, member) * likelihood;
      next(j, member) = q;
      total += q;
      first_moment += q * (a + 0.5 * new_h);
    }
    if (!(total > 0.0) || !math::is_finite(total)) {
      status(member) = Status::non_finite;
      return;
    }
    const double m = first_moment / total;
    double second = 0.0;
    for (int j = 0; j < cells; ++j) {
      const double q = next(j, member) / total, d = new_lo + (j + 0.5) * new_h - m;
      mass(j, member) = q;  // the step reads `mass` only before this loop
      second += q * d * d;
    }
    lower(member) = new_lo;
    width(member) = new_h;
    mean(member, 0) = m;
    covariance(member, 0) = second + new_h * new_h / 12.0;
  }
};

/// Grid reference for scalar discrete-time models with bounded noises: posterior mean (member, 0) and variance
/// of every member of a bank, from the filters' prior (a point prior_mean when prior_cov = 0; else the uniform
/// law with the prior's mean and variance, as Clark's filters start).
template <class ExecSpace, class Model>
class DiscreteGridFilter {
 public:
  using MemSpace = typename ExecSpace::memory_space;
  static_assert(Model::discrete_time && Model::state_dim == 1, "DiscreteGridFilter: scalar discrete-time models");
  static constexpr int default_cells = 400;
  /// Why it cannot run `model` (kernels/reference/exact_reference.hpp): every scalar bounded-noise model.
  static const char* unsupported(const Model&) { return nullptr; }
  /// Bytes allocated per member: the masses (two copies), the grid, the posterior.
  static double bytes_per_member(int cells = default_cells) {
    return sizeof(double) * (2.0 * cells + 4) + sizeof(Status);
  }

  DiscreteGridFilter(const ExecSpace& space, const Model& model, int num_members, int cells = default_cells)
      : space_(space), model_(model), cells_(cells) {
    KUSHNER_INPUT_REQUIRE(cells >= 8, "grid: at least 8 cells (got " << cells << ")");
    mass_ = decltype(mass_)("kushner::discrete_grid_mass", cells, num_members);
    next_ = decltype(next_)("kushner::discrete_grid_next", cells, num_members);
    lower_ = BankScalar<double, MemSpace>("kushner::discrete_grid_lower", num_members);
    width_ = BankScalar<double, MemSpace>("kushner::discrete_grid_width", num_members);
    mean_ = BankVector<MemSpace>("kushner::discrete_grid_mean", num_members, 1);
    covariance_ = BankSymmetric<MemSpace>("kushner::discrete_grid_covariance", num_members, 1);
    status_ = BankScalar<Status, MemSpace>("kushner::discrete_grid_status", num_members);
    // The prior: all mass in one cell at prior_mean (point prior), or spread evenly over mean -+ sqrt(3 P).
    const double m0 = model.prior_mean[0], half = std::sqrt(3.0 * model.prior_cov(0, 0));
    const bool point = !(half > 0.0);
    auto mass = Kokkos::create_mirror_view(mass_);
    auto lower = Kokkos::create_mirror_view(lower_);
    auto width = Kokkos::create_mirror_view(width_);
    auto mean = Kokkos::create_mirror_view(mean_);
    auto cov = Kokkos::create_mirror_view(covariance_);
    for (int member = 0; member < num_members; ++member) {
      for (int j = 0; j < cells; ++j) mass(j, member) = point ? (j == 0 ? 1.0 : 0.0) : 1.0 / cells;
      width(member) = point ? 0.0 : 2.0 * half / cells;
      lower(member) = point ? m0 : m0 - half;  // a point: cell 0 of width 0 at m0
      mean(member, 0) = m0;
      cov(member, 0) = model.prior_cov(0, 0);
    }
    Kokkos::deep_copy(space_, mass_, mass);
    Kokkos::deep_copy(space_, lower_, lower);
    Kokkos::deep_copy(space_, width_, width);
    Kokkos::deep_copy(space_, mean_, mean);
    Kokkos::deep_copy(space_, covariance_, cov);
  }

  /// Step k -> k + 1 with z[k+1] (member, 0).
  void step(long k, double, const BankVector<MemSpace>& z) {
    KUSHNER_REQUIRE(z.extent(0) == mean_.extent(0) && z.extent_int(1) == 1, "z has the wrong shape");
    parallel_for_members("kushner::discrete_grid_step", space_, mean_.extent(0),
                         DiscreteGridStep<Model, MemSpace>{model_, mass_, next_, lower_, width_, z, mean_, covariance_,
                                                           status_, cells_, static_cast<double>(k)});
  }

  const BankVector<MemSpace>& posterior_mean() const { return mean_; }
  const BankSymmetric<MemSpace>& posterior_covariance() const { return covariance_; }
  const BankScalar<Status, MemSpace>& status() const { return status_; }
  int cells() const { return cells_; }

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
  int cells_;
  Kokkos::View<double**, Kokkos::LayoutLeft, MemSpace> mass_, next_;
  BankScalar<double, MemSpace> lower_, width_;
  BankVector<MemSpace> mean_;
  BankSymmetric<MemSpace> covariance_;
  BankScalar<Status, MemSpace> status_;
};

}  // namespace kushner
