#pragma once
// What `kushner compare` shows for a few chosen members, recorded at the run's output times: the truth, each
// filter's estimate with its +-2 sigma band, the particle mean with its 5-95% band (trajectories.csv); and the
// particle density of the first state component (its marginal, for a model of several) of the first chosen
// member against each filter's Gaussian at chosen times (density.csv, snapshot "time"). Beside those, the most
// bimodal particle posterior of x1 seen at any output time after 0 among the first `bimodal_scan_members`
// members (snapshot "most_bimodal", scored by bimodality_score): where a Gaussian filter cannot follow the
// posterior, whatever the chosen times. Only those members are copied to the host, so it costs little next to
// the run.
#include "core/collectives.hpp"
#include "core/errors.hpp"
#include "core/math.hpp"
#include "drivers/csv.hpp"
#include "drivers/run_metadata.hpp"
#include "engine/filter_bank.hpp"
#include "engine/member_share.hpp"
#include "engine/reference_estimator.hpp"
#include "kernels/element_gather.hpp"
#include "kernels/host_copy.hpp"

#include <Kokkos_Core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace kushner {

template <class ExecSpace, class Model>
class TrajectoryRecorder {
 public:
  using MemSpace = typename ExecSpace::memory_space;
  static constexpr int n = Model::state_dim;
  static constexpr int density_bins = 80;
  /// Members 0 .. 31 lie in the first block of 256 (engine/member_share.hpp): one rank holds them all.
  static constexpr int bimodal_scan_members = 32;

  /// The most bimodal snapshot found (score 0: none scanned, or every posterior had one mode).
  struct BimodalSnapshot {
    double score = 0.0, t = 0.0;
    long member = -1, scanned_members = 0;
  };

  /// `members`: the members to follow (each below `num_members`); `density_times`: the density
  /// snapshots are taken at the first output time at or after each of them. In a run over MPI ranks every
  /// rank records the same text: the rank that holds a member writes its rows and sends them to the others.
  TrajectoryRecorder(const std::vector<long>& members, long num_members, std::vector<double> density_times)
      : members_(members), density_times_(std::move(density_times)), share_(member_share(num_members)) {
    for (long m : members_)
      KUSHNER_INPUT_REQUIRE(m >= 0 && m < num_members,
                            "--trajectory-members: member " << m << " is not in 0 .. " << num_members - 1);
    std::sort(density_times_.begin(), density_times_.end());
    if (!density_times_.empty()) bimodal_.scanned_members = std::min<long>(num_members, bimodal_scan_members);
    trajectories_ = "member,t,component,series,estimate,lower,upper\n";
  }

  /// Records output time t. `values`: null, or the values at t of elements(bank) (engine/filter_run.hpp's
  /// OutputObserver: a run without outside estimators, whose bank may be further on).
  template <class TruthModel>
  void operator()(double t, const FilterBank<ExecSpace, Model, TruthModel>& bank,
                  const std::vector<const ReferenceEstimator<MemSpace>*>& outside, const std::vector<double>* values) {
    if (members_.empty()) return;
    std::vector<int> local;  // the chosen and scanned members this rank holds, as indices into its bank
    for (long m : members_)
      if (share_.holds(m)) local.push_back(static_cast<int>(m - share_.first));
    for (long m = 0; m < bimodal_.scanned_members; ++m)
      if (share_.holds(m)) local.push_back(static_cast<int>(m - share_.first));
    std::sort(local.begin(), local.end());
    local.erase(std::unique(local.begin(), local.end()), local.end());
    const ReferenceEstimator<MemSpace>* pf = nullptr;  // the first estimator among `outside` made of particles
    std::optional<ParticleSnapshot> snapshot;          // its particles of `local`
    for (const auto* e : outside) {
      if (pf) break;
      snapshot = e->particle_snapshot(local);
      if (snapshot) pf = e;
    }
    const bool density = pf && next_density_ < density_times_.size() && t >= density_times_[next_density_] - 1e-9;
    // Unless the values came with the call (a segment copied elements(bank)): a first pass for what the rows read,
    // and one gather. Then the rows, which must read every value once.
    if (values == nullptr) {
      std::vector<std::uintptr_t> addresses;
      for (const WatchedElement& e : elements(bank, outside, pf)) addresses.push_back(e.address);
      values = &gather_(ExecSpace(), addresses);
    }
    ElementReader read{nullptr, values};
    for (long member : members_) {
      std::string rows;
      if (share_.holds(member))
        rows = trajectory_rows(t, member, member - share_.first, bank, outside, pf, snapshot, read);
      trajectories_ += collective::broadcast(rows, member_owner(member, share_.total));
    }
    KUSHNER_REQUIRE(read.next == values->size(),
                    "TrajectoryRecorder: " << values->size() << " values for " << read.next << " elements read");
    if (density) {
      while (next_density_ < density_times_.size() && t >= density_times_[next_density_] - 1e-9) ++next_density_;
      const long member = members_.front();
      std::string rows;
      if (share_.holds(member))
        rows = density_rows("time", t, member, member - share_.first, bank, outside, *pf, *snapshot);
      density_ += collective::broadcast(rows, member_owner(member, share_.total));
    }
    // At t = 0 every posterior is the Gaussian prior. The rank holding the scanned members sends the others a
    // snapshot that beats the best so far ("score t member" and its rows), or nothing.
    if (pf && t > 0.0 && bimodal_.scanned_members > 0) {
      std::string update;
      if (share_.holds(0)) {
        BimodalSnapshot best = bimodal_;
        for (long m = 0; m < bimodal_.scanned_members; ++m) {
          const double score = snapshot->bimodality(static_cast<int>(m - share_.first), 0);
          if (score <= best.score) continue;
          best.score = score;
          best.member = m;
        }
        if (best.member != bimodal_.member || best.score != bimodal_.score)
          update =
              format_number(best.score) + " " + std::to_string(best.member) + "\n" +
              density_rows("most_bimodal", t, best.member, best.member - share_.first, bank, outside, *pf, *snapshot);
      }
      update = collective::broadcast(update, member_owner(0, share_.total));
      if (!update.empty()) {
        const std::size_t end = update.find('\n');
        std::istringstream header(update.substr(0, end));
        header >> bimodal_.score >> bimodal_.member;
        bimodal_.t = t;
        bimodal_rows_ = update.substr(end + 1);
      }
    }
  }

  /// The elements of this rank's bank operator() reads at every output time of a run without outside estimators.
  template <class TruthModel>
  std::vector<WatchedElement> elements(const FilterBank<ExecSpace, Model, TruthModel>& bank) const {
    return elements(bank, {}, nullptr);
  }

  const std::string& trajectories_csv() const { return trajectories_; }
  /// Empty unless a density snapshot was taken (a run with the particle filter).
  std::string density_csv() const {
    if (density_.empty() && bimodal_rows_.empty()) return std::string();
    return "snapshot,t,member,x,series,density\n" + density_ + bimodal_rows_;
  }
  const BimodalSnapshot& most_bimodal() const { return bimodal_; }

  /// What a checkpoint holds of it: the text recorded so far and where the snapshots stand.
  void visit_state(StateArchive& archive) {
    archive.scope = "recorder.";
    archive.value("next_density", next_density_);
    archive.value("most_bimodal", bimodal_);
    archive.text("trajectories", trajectories_);
    archive.text("density", density_);
    archive.text("most_bimodal_rows", bimodal_rows_);
    archive.scope.clear();
  }

 private:
  /// The elements the rows of this rank's chosen members read (trajectory_rows' first pass), in their order.
  template <class TruthModel>
  std::vector<WatchedElement> elements(const FilterBank<ExecSpace, Model, TruthModel>& bank,
                                       const std::vector<const ReferenceEstimator<MemSpace>*>& outside,
                                       const ReferenceEstimator<MemSpace>* pf) const {
    std::vector<WatchedElement> read;
    ElementReader record{&read};
    for (long member : members_)
      if (share_.holds(member)) trajectory_rows(0.0, member, member - share_.first, bank, outside, pf, {}, record);
    return read;
  }

  template <class View>
  static auto row(const View& v, long member) {
    return host_copy(Kokkos::subview(v, member, Kokkos::ALL));
  }

  /// How trajectory_rows reads element (row `local`, column) of a bank view: a first pass records where
  /// (`record`), ElementGather copies all of them at once, and a second pass reads the values in the same order.
  struct ElementReader {
    std::vector<WatchedElement>* record = nullptr;
    const std::vector<double>* values = nullptr;
    std::size_t next = 0;
    template <class View>
    double operator()(const View& v, long local, int column) {
      if (record == nullptr) {
        const std::size_t i = next++;
        return i < values->size() ? (*values)[i] : math::quiet_nan();  // too few: operator() refuses after the rows
      }
      record->push_back({element_address(v, local, column), local});
      return 0.0;
    }
  };

  /// Global member `member`, row `local` of this rank's bank, at time t.
  template <class TruthModel>
  static std::string trajectory_rows(double t, long member, long local,
                                     const FilterBank<ExecSpace, Model, TruthModel>& bank,
                                     const std::vector<const ReferenceEstimator<MemSpace>*>& outside,
                                     const ReferenceEstimator<MemSpace>* pf,
                                     const std::optional<ParticleSnapshot>& snapshot, ElementReader& read) {
    std::string rows;
    for (int i = 0; i < n; ++i) {
      const double x = read(bank.truths().state(), local, i);
      add_trajectory(rows, member, t, i, "truth", x, x, x);
    }
    for (const auto& name : bank.filter_names())
      bank.with_slot(name, [&](const auto& slot) { add_gaussian(rows, member, t, name, local, slot.m, slot.P, read); });
    for (const auto* e : outside) {
      if (e == pf) {
        for (int i = 0; i < n; ++i) {
          const double mean = read(pf->mean(), local, i);
          if (read.record != nullptr) continue;
          const std::vector<double> band = snapshot->quantiles(static_cast<int>(local), i, {0.05, 0.95});
          add_trajectory(rows, member, t, i, pf->name(), mean, band[0], band[1]);
        }
      } else {
        add_gaussian(rows, member, t, e->name(), local, e->mean(), e->covariance(), read);
      }
    }
    return rows;
  }

  static void add_trajectory(std::string& rows, long member, double t, int i, const std::string& series,
                             double estimate, double lower, double upper) {
    rows += std::to_string(member) + "," + format_number(t) + "," + std::to_string(i) + "," + series + "," +
            format_number(estimate) + "," + format_number(lower) + "," + format_number(upper) + "\n";
  }

  /// The estimate of row `local` of (m, packed P) with its +-2 sigma band.
  template <class MeanView, class CovarianceView>
  static void add_gaussian(std::string& rows, long member, double t, const std::string& name, long local,
                           const MeanView& m, const CovarianceView& P, ElementReader& read) {
    for (int i = 0; i < n; ++i) {
      const double mean = read(m, local, i);
      const double sd = std::sqrt(std::max(0.0, read(P, local, packed_index(n, i, i))));
      add_trajectory(rows, member, t, i, name, mean, mean - 2.0 * sd, mean + 2.0 * sd);
    }
  }

  /// density.csv's rows of one snapshot (`kind`): the particle histogram of x1 of global member `member` (row
  /// `local` of this rank's bank) at t, each filter's Gaussian on the same bins, and the truth.
  template <class TruthModel>
  static std::string density_rows(const std::string& kind, double t, long member, long local,
                                  const FilterBank<ExecSpace, Model, TruthModel>& bank,
                                  const std::vector<const ReferenceEstimator<MemSpace>*>& outside,
                                  const ReferenceEstimator<MemSpace>& pf, const ParticleSnapshot& snapshot) {
    std::string rows;
    const int column = static_cast<int>(local);
    // The range holds the particle mass (0.1%-99.9%) with a margin, so that the filters' bells show too.
    const std::vector<double> q = snapshot.quantiles(column, 0, {0.001, 0.999});
    const double margin = 0.25 * std::max(q[1] - q[0], 1e-12);
    const double lo = q[0] - margin, hi = q[1] + margin, width = (hi - lo) / density_bins;
    const std::vector<double> histogram = snapshot.histogram(column, 0, lo, hi, density_bins);
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
      bank.with_slot(name, [&](const auto& slot) { bell(name, row(slot.m, local)(0), row(slot.P, local)(0)); });
    for (const auto* e : outside)
      if (e != &pf) bell(e->name(), row(e->mean(), local)(0), row(e->covariance(), local)(0));
    add("truth", row(bank.truths().state(), local)(0), 0.0);
    return rows;
  }

  std::vector<long> members_;
  std::vector<double> density_times_;
  MemberShare share_;
  std::size_t next_density_ = 0;
  BimodalSnapshot bimodal_;
  std::string trajectories_, density_, bimodal_rows_;
  ElementGather<ExecSpace> gather_;
};

}  // namespace kushner
