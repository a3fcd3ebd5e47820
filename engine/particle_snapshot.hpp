#pragma once
// On request, at chosen times: the particle filter's marginal quantiles and a density snapshot (histogram)
// per member. A snapshot copies the particles and normalized weights to the host once (of every member, or of
// a few chosen ones); every statistic below is then computed there, in particle order, so it is
// deterministic. Host code only.
#include "core/errors.hpp"
#include "engine/particle_filter_bank.hpp"
#include "kernels/host_copy.hpp"

#include <Kokkos_Core.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>
#include <vector>

namespace kushner {

/// How bimodal a density histogram is: 0 for one mode, else the height of the second mode over the first's (1:
/// two equal modes). A second mode counts only at least 4 bins from the highest, with the histogram between
/// them dipping to at most half its height; the histogram is first smoothed with weights (1, 2, 1) / 4 so that a
/// bin's sampling noise makes no mode.
inline double bimodality_score(const std::vector<double>& histogram) {
  const int bins = static_cast<int>(histogram.size());
  std::vector<double> h(bins, 0.0);
  for (int b = 0; b < bins; ++b)
    h[b] = 0.5 * histogram[b] + 0.25 * ((b > 0 ? histogram[b - 1] : 0.0) + (b + 1 < bins ? histogram[b + 1] : 0.0));
  std::vector<int> peaks;
  for (int b = 1; b + 1 < bins; ++b)
    if (h[b] >= h[b - 1] && h[b] > h[b + 1]) peaks.push_back(b);
  if (peaks.size() < 2) return 0.0;
  const int top = *std::max_element(peaks.begin(), peaks.end(), [&](int a, int b) { return h[a] < h[b]; });
  double score = 0.0;
  for (int b : peaks) {
    if (std::abs(b - top) < 4) continue;
    const double dip = *std::min_element(h.begin() + std::min(b, top), h.begin() + std::max(b, top) + 1);
    if (dip <= 0.5 * h[b]) score = std::max(score, h[b] / h[top]);
  }
  return score;
}

class ParticleSnapshot {
 public:
  template <class ExecSpace, class Model, class Real>
  explicit ParticleSnapshot(const ParticleFilterBank<ExecSpace, Model, Real>& pf)
      : members_(pf.num_members()),
        particles_(pf.num_particles()),
        dim_(Model::state_dim),
        x_("kushner::snapshot_particles", particles_, members_, dim_),
        w_("kushner::snapshot_weights", particles_, members_) {
    const auto x = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.particles());
    const auto lw = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.log_weights());
    const auto ln = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.log_normalizer());
    for (int m = 0; m < members_; ++m)
      for (int j = 0; j < particles_; ++j) {
        w_(j, m) = std::exp(lw(j, m) - ln(m));
        for (int i = 0; i < dim_; ++i) x_(j, m, i) = x(j, m, i);
      }
    column_.resize(members_);
    std::iota(column_.begin(), column_.end(), 0);
  }

  /// Only the members in `members` (each in range): what a run that follows a few members needs, without
  /// copying the whole bank.
  template <class ExecSpace, class Model, class Real>
  ParticleSnapshot(const ParticleFilterBank<ExecSpace, Model, Real>& pf, const std::vector<int>& members)
      : members_(pf.num_members()),
        particles_(pf.num_particles()),
        dim_(Model::state_dim),
        x_("kushner::snapshot_particles", particles_, members.size(), dim_),
        w_("kushner::snapshot_weights", particles_, members.size()),
        column_(members_, -1) {
    const auto ln = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), pf.log_normalizer());
    for (std::size_t k = 0; k < members.size(); ++k) {
      const int m = members[k];
      KUSHNER_REQUIRE(m >= 0 && m < members_, "snapshot: member " << m << " out of range");
      column_[m] = static_cast<int>(k);
      const auto lw =
          Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), Kokkos::subview(pf.log_weights(), Kokkos::ALL, m));
      const auto x = host_copy(Kokkos::subview(pf.particles(), Kokkos::ALL, m, Kokkos::ALL));
      for (int j = 0; j < particles_; ++j) {
        w_(j, k) = std::exp(lw(j) - ln(m));
        for (int i = 0; i < dim_; ++i) x_(j, k, i) = x(j, i);
      }
    }
  }

  int num_members() const { return members_; }

  /// Weighted quantiles of component i of member m at probabilities `p` (each in [0, 1]): the smallest
  /// particle value whose cumulative weight reaches p (the inverse of the weighted empirical CDF).
  std::vector<double> quantiles(int member, int i, const std::vector<double>& p) const {
    const int c = column(member, i);  // the snapshot's column of the member
    std::vector<int> order(particles_);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return x_(a, c, i) < x_(b, c, i); });
    double total = 0.0;
    for (int j = 0; j < particles_; ++j) total += w_(j, c);
    std::vector<double> out;
    for (double q : p) {
      KUSHNER_INPUT_REQUIRE(q >= 0.0 && q <= 1.0, "quantile: probability must be in [0, 1] (got " << q << ")");
      double cumulative = 0.0;
      double value = x_(order.back(), c, i);
      for (int j : order) {
        cumulative += w_(j, c) / total;
        if (cumulative >= q && w_(j, c) > 0.0) {
          value = x_(j, c, i);
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
    const int c = column(member, i);  // the snapshot's column of the member
    KUSHNER_INPUT_REQUIRE(hi > lo && bins >= 1,
                          "histogram: need lo < hi and bins >= 1 (got " << lo << ", " << hi << ", " << bins << ")");
    std::vector<double> density(bins, 0.0);
    double total = 0.0;
    for (int j = 0; j < particles_; ++j) total += w_(j, c);
    const double width = (hi - lo) / bins;
    for (int j = 0; j < particles_; ++j) {
      const double v = x_(j, c, i);
      if (!(v >= lo && v < hi)) continue;
      const int b = std::min(bins - 1, static_cast<int>((v - lo) / width));
      density[b] += w_(j, c) / total / width;
    }
    return density;
  }

  /// bimodality_score of component i of member m on `bins` bins over its weighted mean +- 4 standard deviations
  /// (computed in one pass, without the sort quantiles() needs: cheap enough to scan many members).
  double bimodality(int member, int i, int bins = 60) const {
    const int c = column(member, i);
    double total = 0.0, mean = 0.0, square = 0.0;
    for (int j = 0; j < particles_; ++j) {
      total += w_(j, c);
      mean += w_(j, c) * x_(j, c, i);
    }
    mean /= total;
    for (int j = 0; j < particles_; ++j) square += w_(j, c) * (x_(j, c, i) - mean) * (x_(j, c, i) - mean);
    const double sd = std::sqrt(square / total);
    if (!(sd > 0.0)) return 0.0;
    return bimodality_score(histogram(member, i, mean - 4.0 * sd, mean + 4.0 * sd, bins));
  }

 private:
  /// The snapshot's column of `member`, after checking that the snapshot holds it.
  int column(int member, int i) const {
    KUSHNER_REQUIRE(member >= 0 && member < members_ && i >= 0 && i < dim_ && column_[member] >= 0,
                    "member " << member << " component " << i << " not in this snapshot");
    return column_[member];
  }
  int members_, particles_, dim_;
  Kokkos::View<double***, Kokkos::LayoutLeft, Kokkos::HostSpace> x_;
  Kokkos::View<double**, Kokkos::LayoutLeft, Kokkos::HostSpace> w_;
  std::vector<int> column_;  // member -> column of x_ and w_, -1 when not copied
};

}  // namespace kushner
