#pragma once
// On request, at chosen times: the particle filter's marginal quantiles and a density snapshot (histogram)
// per member. A snapshot copies the particles and normalized weights to the host once; every statistic
// below is then computed there, in particle order, so it is deterministic. Host code only.
#include "kernels/errors.hpp"
#include "kernels/particle_filter/particle_filter_bank.hpp"

#include <Kokkos_Core.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

namespace kushner {

class ParticleSnapshot {
 public:
  template <class ExecSpace, class Model>
  explicit ParticleSnapshot(const ParticleFilterBank<ExecSpace, Model>& pf)
      : members_(pf.num_members()), particles_(pf.num_particles()), dim_(Model::state_dim),
        x_(Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.particles())),
        w_("kushner::snapshot_weights", particles_, members_) {
    const auto lw = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.log_weights());
    const auto ln = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.log_normalizer());
    for (int m = 0; m < members_; ++m)
      for (int j = 0; j < particles_; ++j) w_(j, m) = std::exp(lw(j, m) - ln(m));
  }

  int num_members() const { return members_; }

  /// Weighted quantiles of component i of member m at probabilities `p` (each in [0, 1]): the smallest
  /// particle value whose cumulative weight reaches p (the inverse of the weighted empirical CDF).
  std::vector<double> quantiles(int member, int i, const std::vector<double>& p) const {
    check(member, i);
    std::vector<int> order(particles_);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return x_(a, member, i) < x_(b, member, i); });
    double total = 0.0;
    for (int j = 0; j < particles_; ++j) total += w_(j, member);
    std::vector<double> out;
    for (double q : p) {
      KUSHNER_INPUT_REQUIRE(q >= 0.0 && q <= 1.0, "quantile: probability must be in [0, 1] (got " << q << ")");
      double c = 0.0;
      double value = x_(order.back(), member, i);
      for (int j : order) {
        c += w_(j, member) / total;
        if (c >= q && w_(j, member) > 0.0) {
          value = x_(j, member, i);
          break;
        }
      }
      out.push_back(value);
    }
    return out;
  }

  /// Histogram of component i of member m: the posterior probability of each of `bins` equal bins on
  /// [lo, hi), divided by the bin width (a density); mass outside [lo, hi) is left out.
  std::vector<double> histogram(int member, int i, double lo, double hi, int bins) const {
    check(member, i);
    KUSHNER_INPUT_REQUIRE(hi > lo && bins >= 1, "histogram: need lo < hi and bins >= 1 (got " << lo << ", " << hi
                                                                                          << ", " << bins << ")");
    std::vector<double> density(bins, 0.0);
    double total = 0.0;
    for (int j = 0; j < particles_; ++j) total += w_(j, member);
    const double width = (hi - lo) / bins;
    for (int j = 0; j < particles_; ++j) {
      const double v = x_(j, member, i);
      if (!(v >= lo && v < hi)) continue;
      const int b = std::min(bins - 1, static_cast<int>((v - lo) / width));
      density[b] += w_(j, member) / total / width;
    }
    return density;
  }

 private:
  void check(int member, int i) const {
    KUSHNER_REQUIRE(member >= 0 && member < members_ && i >= 0 && i < dim_,
                    "member " << member << " component " << i << " out of range");
  }
  int members_, particles_, dim_;
  Kokkos::View<double***, Kokkos::LayoutLeft, Kokkos::HostSpace> x_;
  Kokkos::View<double**, Kokkos::LayoutLeft, Kokkos::HostSpace> w_;
};

}  // namespace kushner
