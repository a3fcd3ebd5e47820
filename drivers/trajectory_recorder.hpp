#pragma once
// What `kushner compare` shows for a few chosen members, recorded at the run's output times: the truth, each
// filter's estimate with its +-2 sigma band, the particle mean with its 5-95% band (trajectories.csv); and the
// particle density of the first state component (its marginal, for a model of several) of the first chosen
// member against each filter's Gaussian at chosen times (density.csv, snapshot "time"). Beside those, the most
// bimodal particle posterior of x1 seen at any output time after 0 among the first `bimodal_scan_members`
// members (snapshot "most_bimodal", scored by bimodality_score): where a Gaussian filter cannot follow the
// posterior, whatever the chosen times. Only those members are copied to the host, so it costs little next to
// the run.
#include "core/errors.hpp"
#include "drivers/csv.hpp"
#include "drivers/run_metadata.hpp"
#include "engine/filter_bank.hpp"
#include "engine/reference_estimator.hpp"
#include "kernels/host_copy.hpp"

#include <Kokkos_Core.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace kushner {

template <class ExecSpace, class Model>
class TrajectoryRecorder {
 public:
  using MemSpace = typename ExecSpace::memory_space;
  static constexpr int n = Model::state_dim;
  static constexpr int density_bins = 80;
  static constexpr int bimodal_scan_members = 32;

  /// The most bimodal snapshot found (score 0: none scanned, or every posterior had one mode).
  struct BimodalSnapshot {
    double score = 0.0, t = 0.0;
    long member = -1, scanned_members = 0;
  };

  /// `members`: the members to follow (each below `num_members`); `density_times`: the density
  /// snapshots are taken at the first output time at or after each of them.
  TrajectoryRecorder(const std::vector<long>& members, long num_members, std::vector<double> density_times)
      : members_(members), density_times_(std::move(density_times)) {
    for (long m : members_)
      KUSHNER_INPUT_REQUIRE(m >= 0 && m < num_members,
                            "--trajectory-members: member " << m << " is not in 0 .. " << num_members - 1);
    std::sort(density_times_.begin(), density_times_.end());
    if (!density_times_.empty()) bimodal_.scanned_members = std::min<long>(num_members, bimodal_scan_members);
    trajectories_ = "member,t,component,series,estimate,lower,upper\n";
  }

  template <class TruthModel>
  void operator()(double t, const FilterBank<ExecSpace, Model, TruthModel>& bank,
                  const std::vector<const ReferenceEstimator<MemSpace>*>& outside) {
    std::vector<int> members(members_.begin(), members_.end());
    if (members.empty()) return;
    std::vector<int> copied = members;  // the followed members and those scanned for a bimodal posterior
    for (int m = 0; m < bimodal_.scanned_members; ++m) copied.push_back(m);
    std::sort(copied.begin(), copied.end());
    copied.erase(std::unique(copied.begin(), copied.end()), copied.end());
    const ReferenceEstimator<MemSpace>* pf = nullptr;  // the first estimator among `outside` made of particles
    std::optional<ParticleSnapshot> snapshot;          // its particles of `copied`
    for (const auto* e : outside) {
      if (pf) break;
      snapshot = e->particle_snapshot(copied);
      if (snapshot) pf = e;
    }
    const bool density = pf && next_density_ < density_times_.size() && t >= density_times_[next_density_] - 1e-9;
    for (int member : members) {
      const auto x = row(bank.truths().state(), member);
      for (int i = 0; i < n; ++i) add_trajectory(member, t, i, "truth", x(i), x(i), x(i));
      for (const auto& name : bank.filter_names())
        bank.with_slot(
            name, [&](const auto& slot) { add_gaussian(member, t, name, row(slot.m, member), row(slot.P, member)); });
      for (const auto* e : outside) {
        if (e == pf) {
          const auto mean = row(pf->mean(), member);
          for (int i = 0; i < n; ++i) {
            const std::vector<double> band = snapshot->quantiles(member, i, {0.05, 0.95});
            add_trajectory(member, t, i, pf->name(), mean(i), band[0], band[1]);
          }
        } else {
          add_gaussian(member, t, e->name(), row(e->mean(), member), row(e->covariance(), member));
        }
      }
    }
    if (density) {
      while (next_density_ < density_times_.size() && t >= density_times_[next_density_] - 1e-9) ++next_density_;
      density_ += density_rows("time", t, members.front(), bank, outside, *pf, *snapshot);
    }
    // At t = 0 every posterior is the Gaussian prior.
    if (pf && t > 0.0)
      for (int m = 0; m < bimodal_.scanned_members; ++m) {
        const double score = snapshot->bimodality(m, 0);
        if (score <= bimodal_.score) continue;
        bimodal_.score = score;
        bimodal_.t = t;
        bimodal_.member = m;
        bimodal_rows_ = density_rows("most_bimodal", t, m, bank, outside, *pf, *snapshot);
      }
  }

  const std::string& trajectories_csv() const { return trajectories_; }
  /// Empty unless a density snapshot was taken (a run with the particle filter).
  std::string density_csv() const {
    if (density_.empty() && bimodal_rows_.empty()) return std::string();
    return "snapshot,t,member,x,series,density\n" + density_ + bimodal_rows_;
  }
  const BimodalSnapshot& most_bimodal() const { return bimodal_; }

 private:
  template <class View>
  static auto row(const View& v, long member) {
    return host_copy(Kokkos::subview(v, member, Kokkos::ALL));
  }

  void add_trajectory(long member, double t, int i, const std::string& series, double estimate, double lower,
                      double upper) {
    trajectories_ += std::to_string(member) + "," + format_number(t) + "," + std::to_string(i) + "," + series + "," +
                     format_number(estimate) + "," + format_number(lower) + "," + format_number(upper) + "\n";
  }

  template <class MeanRow, class CovarianceRow>
  void add_gaussian(long member, double t, const std::string& name, const MeanRow& m, const CovarianceRow& P) {
    for (int i = 0; i < n; ++i) {
      const double sd = std::sqrt(std::max(0.0, P(packed_index(n, i, i))));
      add_trajectory(member, t, i, name, m(i), m(i) - 2.0 * sd, m(i) + 2.0 * sd);
    }
  }

  /// density.csv's rows of one snapshot: the particle histogram of x1 of `member` at t, each filter's Gaussian
  /// on the same bins, and the truth.
  template <class TruthModel>
  std::string density_rows(const std::string& kind, double t, int member,
                           const FilterBank<ExecSpace, Model, TruthModel>& bank,
                           const std::vector<const ReferenceEstimator<MemSpace>*>& outside,
                           const ReferenceEstimator<MemSpace>& pf, const ParticleSnapshot& snapshot) {
    std::string rows;
    // The range holds the particle mass (0.1%-99.9%) with a margin, so that the filters' bells show too.
    const std::vector<double> q = snapshot.quantiles(member, 0, {0.001, 0.999});
    const double margin = 0.25 * std::max(q[1] - q[0], 1e-12);
    const double lo = q[0] - margin, hi = q[1] + margin, width = (hi - lo) / density_bins;
    const std::vector<double> histogram = snapshot.histogram(member, 0, lo, hi, density_bins);
    auto add = [&](const std::string& series, double x, double d) {
      rows += kind + "," + format_number(t) + "," + std::to_string(member) + "," + format_number(x) + "," + series +
              "," + format_number(d) + "\n";
    };
    for (int b = 0; b < density_bins; ++b) add(pf.name(), lo + (b + 0.5) * width, histogram[b]);
    auto bell = [&](const std::string& name, double mean, double variance) {
      if (!(variance > 0.0)) return;
      for (int b = 0; b < density_bins; ++b) {
        const double x = lo + (b + 0.5) * width, z = (x - mean) / std::sqrt(variance);
        add(name, x, std::exp(-0.5 * z * z) / std::sqrt(2.0 * M_PI * variance));
      }
    };
    for (const auto& name : bank.filter_names())
      bank.with_slot(name, [&](const auto& slot) { bell(name, row(slot.m, member)(0), row(slot.P, member)(0)); });
    for (const auto* e : outside)
      if (e != &pf) bell(e->name(), row(e->mean(), member)(0), row(e->covariance(), member)(0));
    add("truth", row(bank.truths().state(), member)(0), 0.0);
    return rows;
  }

  std::vector<long> members_;
  std::vector<double> density_times_;
  std::size_t next_density_ = 0;
  BimodalSnapshot bimodal_;
  std::string trajectories_, density_, bimodal_rows_;
};

}  // namespace kushner
