#pragma once
// The bank of truths and filters on one execution space: the truths (engine/truth_bank.hpp), every
// filter the model supports as a slot (kernels/filters/filter_slot.hpp) with the selected ones allocated and
// enabled, the fused step kernel, and the reductions behind the reported metrics. Estimators outside the bank
// (particle filter, exact filters: engine/reference_estimator.hpp) step on the same dy right after it and are
// scored like filters; one of them may be the reference that every other estimate is measured against. Where the
// reference takes two steps in one pass (the particle filter on a GPU), step_pair takes two bank steps and scores
// the first one behind. Reductions go through ensemble_moments (fixed-order blocks), so every number is the same
// on any number of threads.
#include "engine/reference_estimator.hpp"
#include "engine/shared_instances.hpp"
#include "engine/truth_bank.hpp"
#include "kernels/element_gather.hpp"
#include "kernels/ensemble_moments.hpp"
#include "kernels/filters/filter_bank_segment.hpp"
#include "kernels/filters/filter_bank_step.hpp"
#include "kernels/filters/filter_list.hpp"
#include "kernels/filters/filter_metrics.hpp"
#include "kernels/for_each_member.hpp"
#include "kernels/queue_mark.hpp"

#include <Kokkos_Core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

namespace kushner {

/// A mean over members with its Monte Carlo standard error.
struct Estimate {
  double value = 0.0, standard_error = 0.0;
  long members = 0;  // how many members it averages
};

/// One filter at one output time.
struct FilterSnapshot {
  double rmse_truth = 0.0;  // sqrt of the mean over scored members of |m - x|^2
  double rmse_truth_se = 0.0;
  double nees = 0.0;  // mean over members with positive definite P
  double nees_se = 0.0;
  double rmse_ref = 0.0;  // against the reference mean, when there is one
  double rmse_ref_se = 0.0;
  long diverged = 0;  // members whose filter has diverged by now (their truth not escaped)
};

/// One filter over the whole run: time-and-ensemble means over the members scored at the end.
struct FilterScores {
  Estimate rmse_truth;  // root of the time-and-ensemble mean squared error; SE by the delta method
  Estimate nees;        // mean NEES (per member, the time average over points where P is positive definite)
  Estimate rmse_ref;
  long diverged = 0, not_positive_definite = 0, non_finite = 0;  // among members whose truth did not escape
};

/// Selects filter Filter in its slot: the filter made by its pre-pass (`ready`) or by Filter::create with
/// `options` (and the run's seed, for a filter that draws random numbers), its views for `members` members, every
/// member at the model's prior. Shared by the filter bank and the closed loops of `kushner control`
/// (engine/control/closed_loop.hpp).
template <class Filter, class MemSpace, class Model>
void enable_filter_slot(FilterSlot<Filter, MemSpace>& slot, const Model& model, long members,
                        const OptionValues& options, const std::optional<Filter>& ready, Seed seed) {
  constexpr int n = Model::state_dim;
  slot.enabled = true;
  slot.filter =
      ready ? *ready : create_filter<Filter>(options.with_defaults(filter_options<Filter>()), model, members, seed);
  slot.m = BankVector<MemSpace>(std::string("kushner::m_") + Filter::name, members, n);
  slot.P = BankSymmetric<MemSpace>(std::string("kushner::P_") + Filter::name, members, packed_size(n));
  slot.status = BankScalar<Status, MemSpace>(std::string("kushner::status_") + Filter::name, members);
  slot.score = BankVector<MemSpace>(std::string("kushner::score_") + Filter::name, members, num_score_columns);
  slot.snapshot = BankVector<MemSpace>(std::string("kushner::snapshot_") + Filter::name, members, num_snapshot_columns);
  const auto mh = Kokkos::create_mirror_view(slot.m);
  const auto Ph = Kokkos::create_mirror_view(slot.P);
  for (long member = 0; member < members; ++member) {
    for (int i = 0; i < n; ++i) mh(member, i) = model.prior_mean[i];
    for (int i = 0; i < n; ++i)
      for (int j = i; j < n; ++j) Ph(member, packed_index(n, i, j)) = model.prior_cov(i, j);
  }
  Kokkos::deep_copy(slot.m, mh);
  Kokkos::deep_copy(slot.P, Ph);
}

/// Calls f with each filter's slot of `slots` (host side: what is selected, its views, its summary).
template <class F, class MemSpace, class... Filters>
void for_each_filter_slot(FilterSlots<MemSpace, Filters...>& slots, F&& f) {
  (f(static_cast<FilterSlot<Filters, MemSpace>&>(slots)), ...);
}
template <class F, class MemSpace, class... Filters>
void for_each_filter_slot(const FilterSlots<MemSpace, Filters...>& slots, F&& f) {
  (f(static_cast<const FilterSlot<Filters, MemSpace>&>(slots)), ...);
}

/// Enables the slot of the filter called `name` (enable_filter_slot, with its pre-pass's filter where `prepared`
/// has one); false when no slot has that name (the caller says why in its own words).
template <class Slots, class Prepared, class Model>
bool enable_named_filter_slot(Slots& slots, const std::string& name, const Model& model, long members,
                              const OptionValues& options, const Prepared& prepared, Seed seed) {
  bool found = false;
  for_each_filter_slot(slots, [&](auto& slot) {
    using Filter = decltype(slot.filter);
    if (name != Filter::name) return;
    found = true;
    enable_filter_slot(slot, model, members, options, std::get<std::optional<Filter>>(prepared), seed);
  });
  return found;
}

/// `TruthModel`: the truths' model type, Model unless the truths follow another system of the same dimensions
/// (kernels/filters/filter_bank_step.hpp).
template <class ExecSpace, class Model, class TruthModel = Model>
class FilterBank {
 public:
  using MemSpace = typename ExecSpace::memory_space;
  static constexpr int n = Model::state_dim, p = Model::obs_dim;

 private:
  template <class Tuple>
  struct Kernels;
  template <class... Filters>
  struct Kernels<std::tuple<Filters...>> {
    using Slots = FilterSlots<MemSpace, Filters...>;
    using Step = FilterBankStep<Model, TruthModel, MemSpace, Filters...>;
    using Initial = FilterBankInitialScore<Model, MemSpace, Filters...>;
    using Reference = FilterBankReferenceScore<Model, MemSpace, BankVector<MemSpace>, Filters...>;
    using Prepared = std::tuple<std::optional<Filters>...>;
  };
  using K = Kernels<SupportedFilters<Model, MemSpace>>;

 public:
  /// Filters made before the bank (by their pre-pass, or by hand in tests): std::get<std::optional<Filter>>.
  /// The bank creates the others with Filter::create.
  using PreparedFilters = typename K::Prepared;

  /// Bytes the bank allocates per member for `filters` filters: the truth and its observation increments, and
  /// per filter its estimate, covariance, status, scores and snapshot (plus the per-member scores at the end).
  static double bytes_per_member(long filters) {
    const double per_filter =
        sizeof(double) * (n + packed_size(n) + num_score_columns + num_snapshot_columns) + sizeof(Status);
    return sizeof(double) * (n + p + num_member_score_columns) + sizeof(Status) +
           static_cast<double>(filters) * per_filter;
  }

  /// Bytes the selected filters among `filters` allocate per member for state of their own (EnKBF's ensembles,
  /// ASRE's iterates, ...) with settings `options`, beyond bytes_per_member.
  static double own_bytes_per_member(const std::vector<std::string>& filters, const OptionValues& options) {
    double bytes = 0.0;
    for_each_filter_type<Model, MemSpace>([&](auto* tag) {
      using Filter = std::remove_pointer_t<decltype(tag)>;
      if constexpr (detail::has_own_bytes<Filter>::value)
        if (std::find(filters.begin(), filters.end(), Filter::name) != filters.end())
          bytes += Filter::own_bytes_per_member(options.with_defaults(filter_options<Filter>()));
    });
    return bytes;
  }

  /// `filters`: names of filters the model supports (supported_filters, engine/filter_catalog.hpp), in report
  /// order; `options`: their settings (declared defaults where absent). The truths follow truth_model, the
  /// filters filter_model (the same in most runs; tests set them apart to show that a test can fail, and
  /// `kushner reproduce` runs filters of a Taylor model on the system it approximates).
  FilterBank(const ExecSpace& space, const TruthModel& truth_model, const Model& filter_model, long members, Seed seed,
             const std::vector<std::string>& filters, const OptionValues& options = {},
             const PreparedFilters& prepared = {});

  /// Scores every filter against `reference` from now on (call before the first step and before
  /// add_estimator). The bank steps it after each of its own steps (once, also when it is an estimator).
  void set_reference(ReferenceEstimator<MemSpace>* reference);

  /// Steps `estimator` after every bank step and scores it like a filter, named estimator->name() (call
  /// before the first step; the bank does not own it).
  void add_estimator(ReferenceEstimator<MemSpace>* estimator);

  /// Step k, over [k dt, (k + 1) dt]; `record`: (k + 1) dt is an output time.
  void step(long k, double dt, bool record);

  /// Whether a run should call step_pair: the reference advances in pairs (ReferenceEstimator::advances_in_pairs).
  bool steps_in_pairs() const { return reference_ != nullptr && reference_->advances_in_pairs(); }

  /// Steps k and k + 1 (`record`: (k + 2) dt is an output time), the reference taking both in one advance_pair.
  /// Step k's scores against the reference and the outside estimators' scores wait for it: what they read of step k
  /// (the truths, their statuses and dy, each filter's m, status and snapshot columns) is kept before the bank takes
  /// step k + 1. Every score gets the same terms in the same order as step(k, dt, first_output) then step(k + 1,
  /// dt, record), so the numbers are those of the two steps wherever the reference's pair is
  /// (ParticleFilterBank::step_pair). `first_output`: the names of the filters whose snapshots at (k + 1) dt, an
  /// output time, are started in the pair (as start_snapshots(*first_output) after step k would): finish_snapshots
  /// gives them after those started before the call and before those started after it. An observer that reads the
  /// bank at (k + 1) dt cannot run then: the bank is at (k + 2) dt (engine/filter_run.hpp takes single steps).
  void step_pair(long k, double dt, bool record, const std::vector<std::string>* first_output = nullptr);

  /// Bytes step_pair keeps per member for `filters` filters: a step's truth, dy and statuses, each filter's m,
  /// status and snapshot columns.
  static double step_pair_bytes_per_member(long filters) {
    return sizeof(double) * (n + p) + sizeof(Status) +
           static_cast<double>(filters) * (sizeof(double) * (n + num_snapshot_columns) + sizeof(Status));
  }

  /// Whether start_segment may run: no estimator steps beside the bank.
  bool steps_in_segments() const { return reference_ == nullptr && estimators_.empty(); }

  /// A bank in host memory (stepped in chunks of SIMD lanes).
  static constexpr bool host_bank = Kokkos::SpaceAccessibility<Kokkos::HostSpace, MemSpace>::accessible;
  /// Whether start_segment runs its team form (FilterBankTeamSegment: a GPU's) rather than the host's chunk form
  /// (FilterBankSegment); a device bank runs only the team form. The tests run the team form on the host as well.
  bool segment_teams() const { return segment_teams_; }
  void set_segment_teams(bool teams) {
    KUSHNER_REQUIRE(teams || host_bank, "set_segment_teams: a device bank takes its segments in teams only");
    segment_teams_ = teams;
  }

  /// Steps a segment takes at most (run_filters): 16 steps keep a block's columns in a core's cache for 16 times
  /// fewer trips to memory, and their block statistics (output steps) in a few MB.
  static constexpr int segment_steps = 16;

  /// Queues steps k .. k + outputs.size() - 1 in one pass over blocks of members (temporal blocking:
  /// kernels/filters/filter_bank_segment.hpp), with the numbers of step() one step at a time (steps_in_segments();
  /// on a GPU up to the multiply-adds nvcc contracts; at most team_segment_max_steps steps in the team form).
  /// outputs[s] != 0: step k + s ends at an output time. finish_segment waits for the oldest started segment's outputs
  /// and returns, for each in order, snapshots(names) and the values of the `watched` elements (element_address of
  /// this bank's views, members indexed in this bank) at its time: each block copies its own elements as it takes
  /// the output step (an observer of a few members read them between steps taken one at a time by their block first,
  /// a launch and a wait per step: 0.72-0.77x the rate of the bank unwatched on an H200). finish_segment is a
  /// collective call over the ranks, as finish_snapshots is. A second segment may be started before the first is
  /// finished: engine/filter_run.hpp queues the next segment first, so that on a GPU the host merges one segment's
  /// outputs while the device takes the next (waiting for them at once left the device idle meanwhile). Where a
  /// segment's outputs are merged as it is taken (the host's forms, several ranks), start_segment waits for them.
  void start_segment(long k, double dt, const std::vector<char>& outputs, const std::vector<std::string>& names,
                     const std::vector<WatchedElement>& watched = {});
  struct SegmentOutput {
    std::vector<FilterSnapshot> snapshots;
    std::vector<double> watched;
  };
  std::vector<SegmentOutput> finish_segment();

  /// The elements of `members` (of this bank) to watch in a segment (start_segment), member by member: the truth's
  /// state, then each of `filters`' m and every packed entry of P, row by row. (The trajectory recorder watches its own
  /// list: the means and variances its rows read.)
  std::vector<WatchedElement> member_elements(const std::vector<long>& members,
                                              const std::vector<std::string>& filters) const {
    std::vector<WatchedElement> elements;
    for (const long member : members) {
      const auto add = [&](const auto& view) {
        for (int i = 0; i < static_cast<int>(view.extent(1)); ++i)
          elements.push_back({element_address(view, member, i), member});
      };
      add(truths_.state());
      for (const auto& name : filters)
        with_slot(name, [&](const auto& slot) {
          add(slot.m);
          add(slot.P);
        });
    }
    return elements;
  }

  const TruthBank<ExecSpace, TruthModel>& truths() const { return truths_; }
  /// (member): non_finite once the member's truth escaped to infinity.
  const BankScalar<Status, MemSpace>& truth_status() const { return truth_status_; }

  /// Calls f(slot) with the slot of filter `name` (a selected one).
  template <class F>
  void with_slot(const std::string& name, F&& f) const {
    with_slot_in(slots_, name, f);
  }

  /// The selected filters of the bank (not the outside estimators), in slot order.
  std::vector<std::string> filter_names() const {
    std::vector<std::string> names;
    for_each_filter_slot(slots_, [&](const auto& slot) {
      if (slot.enabled) names.push_back(decltype(slot.filter)::name);
    });
    return names;
  }

  /// Whether any of the bank's filters is selected (the outside estimators aside).
  bool any_filter_enabled() const {
    bool any = false;
    for_each_filter_slot(slots_, [&](const auto& slot) { any = any || slot.enabled; });
    return any;
  }

  /// The slot of filter type Filter (one the model supports).
  template <template <class, class> class Filter>
  const FilterSlot<Filter<Model, MemSpace>, MemSpace>& slot() const {
    return static_cast<const FilterSlot<Filter<Model, MemSpace>, MemSpace>&>(slots_);
  }

  /// What filter `name` (a selected one) adds to its summary (kernels/filters/filter_protocol.hpp).
  Fields summary_fields(const std::string& name) const {
    Fields fields;
    for_each_filter_slot(slots_, [&](const auto& slot) {
      if (slot.enabled && name == decltype(slot.filter)::name) fields = filter_summary_fields(slot.filter);
    });
    return fields;
  }

  /// Per member: whether filter `name` and the member's truth are still finite and well defined.
  std::vector<char> members_ok(const std::string& name) const;

  /// Metrics of filter `name` at the latest output time.
  FilterSnapshot snapshot(const std::string& name) const { return snapshots({name}).front(); }

  /// snapshot() of every filter of `names`: the moments of all their snapshot columns and their divergence counts
  /// in one launch (ColumnMoments with NotOkMembers), whatever the number of filters.
  std::vector<FilterSnapshot> snapshots(const std::vector<std::string>& names) const {
    KUSHNER_REQUIRE(pending_.empty(), "snapshots: started snapshots are not finished");
    start_snapshots(names);
    return finish_snapshots();
  }

  /// snapshots() in two halves: start_snapshots queues the reductions of the bank's present time and their copies
  /// to the host; finish_snapshots waits for the oldest started (not for work queued since) and gives its snapshots.
  /// Between the two the bank may take its next steps: on a GPU the host's merge then runs beside them
  /// (engine/filter_run.hpp).
  void start_snapshots(const std::vector<std::string>& names) const;
  std::vector<FilterSnapshot> finish_snapshots() const;

  /// Metrics of filter `name` over the run so far: `points` time points have been scored (steps + 1).
  FilterScores scores(const std::string& name, long points) const;

  /// Saves or loads the bank's state for a checkpoint: truths, per filter its m, P, status, scores,
  /// snapshot and own state, per outside estimator its scores (the estimators save themselves). Draws are keyed
  /// by step, so nothing else carries from one step to the next.
  void visit_state(StateArchive& archive);

  /// Members whose truth escaped to infinity (left out of every metric).
  long truths_escaped() const;

 private:
  struct Estimator {
    ReferenceEstimator<MemSpace>* estimator = nullptr;
    std::string name;
    FilterSlot<ExternalEstimator, MemSpace> slot;  // m, P, status: the estimator's views
  };

  /// What the scores of one time read besides the estimates: the truths and their statuses, the reference's mean
  /// and status (empty without a reference).
  struct ScoredTime {
    BankVector<MemSpace> truth;
    BankScalar<Status, MemSpace> truth_status;
    BankVector<MemSpace> reference;
    BankScalar<Status, MemSpace> reference_status;
  };
  ScoredTime now() const {
    if (!reference_) return {truths_.state(), truth_status_, {}, {}};
    return {truths_.state(), truth_status_, reference_->mean(), reference_->status()};
  }

  /// step_pair's copy of step k: truths, statuses, dy, and slots whose m, status and snapshot are copies of step
  /// k's (their scores and filters are the bank's own).
  struct KeptStep {
    BankVector<MemSpace> truth, dy;
    BankScalar<Status, MemSpace> truth_status;
    typename K::Slots slots;
  };

  /// `snapshots`: step k ends at an output time, so its snapshot columns are kept too (step k + 1 writes the
  /// bank's own when it ends at one).
  void keep_step(bool snapshots) {
    if (kept_.truth.extent(0) == 0) {
      kept_.truth = BankVector<MemSpace>("kushner::truth_kept", members_, n);
      kept_.dy = BankVector<MemSpace>("kushner::dy_kept", members_, p);
      kept_.truth_status = BankScalar<Status, MemSpace>("kushner::truth_status_kept", members_);
      kept_.slots = slots_;
      for_each_kept_slot([&](auto& kept, const auto& slot) {
        if (!slot.enabled) return;
        const std::string name = decltype(slot.filter)::name;
        kept.m = BankVector<MemSpace>("kushner::m_kept_" + name, members_, n);
        kept.status = BankScalar<Status, MemSpace>("kushner::status_kept_" + name, members_);
        kept.snapshot = BankVector<MemSpace>("kushner::snapshot_kept_" + name, members_, num_snapshot_columns);
      });
    }
    parallel_for_members("kushner::keep_truth_step", space_, members_,
                         KeepTruthStep<MemSpace>{truths_.state(), truths_.observations(), truth_status_, kept_.truth,
                                                 kept_.dy, kept_.truth_status});
    for_each_kept_slot([&](auto& kept, const auto& slot) {
      if (!slot.enabled) return;
      Kokkos::deep_copy(space_, kept.m, slot.m);
      Kokkos::deep_copy(space_, kept.status, slot.status);
      if (snapshots) Kokkos::deep_copy(space_, kept.snapshot, slot.snapshot);
    });
  }
  template <class F>
  void for_each_kept_slot(F&& f) {
    for_each_kept_slot_impl(f, static_cast<SupportedFilters<Model, MemSpace>*>(nullptr));
  }
  template <class F, class... Filters>
  void for_each_kept_slot_impl(F& f, std::tuple<Filters...>*) {
    (f(static_cast<FilterSlot<Filters, MemSpace>&>(kept_.slots),
       static_cast<const FilterSlot<Filters, MemSpace>&>(slots_)),
     ...);
  }

  /// with_slot among `slots` (the bank's own, or kept_.slots) and the outside estimators' slots.
  template <class F>
  void with_slot_in(const typename K::Slots& slots, const std::string& name, F&& f) const {
    bool found = false;
    for_each_filter_slot(slots, [&](const auto& slot) {
      if (slot.enabled && name == decltype(slot.filter)::name) {
        found = true;
        f(slot);
      }
    });
    for (const auto& e : estimators_)
      if (!found && e.name == name) {
        found = true;
        f(e.slot);
      }
    KUSHNER_REQUIRE(found, "filter '" << name << "' is not in this bank");
  }

  /// start_snapshots of the bank's filters in `slots` (the bank's own, or kept_.slots in a step pair) and of the
  /// outside estimators, the truths' statuses `truth_status`.
  void start_snapshots_of(const std::vector<std::string>& names, const typename K::Slots& slots,
                          const BankScalar<Status, MemSpace>& truth_status) const;

  bool scored_against_reference(const std::string& name) const {
    return reference_ != nullptr && name != reference_->name();
  }

  typename K::Step step_kernel(long k, double dt, bool record) const {
    const auto step = static_cast<std::uint32_t>(k);
    return {
        TruthStep<TruthModel, MemSpace>{truth_model_, truths_.state(), truths_.observations(), k * dt, dt, seed_, step},
        filter_model_, truth_status_, slots_, record};
  }

  void run_step_kernel(long k, double dt, bool record) {
    parallel_for_members("kushner::filter_bank_step", space_, members_, step_kernel(k, dt, record));
  }

  /// The snapshots of `names` (their columns start at first[i] in `merged`: squared error, NEES[, reference]).
  std::vector<FilterSnapshot> snapshots_of(const MergedBlocks& merged, const std::vector<std::string>& names,
                                           const std::vector<int>& first) const;

  /// Scores every filter against the reference, and every outside estimator, at the time the bank is at.
  void score_now(bool record) {
    const ScoredTime time = now();
    if (reference_) score_reference(slots_, time, record);
    for (auto& e : estimators_) score_estimator(e, e.estimator->estimate(), time, record);
  }

  void score_estimator(Estimator& e, const EstimateViews<MemSpace>& estimate, const ScoredTime& time, bool record) {
    e.slot.m = estimate.mean;
    e.slot.P = estimate.covariance;
    e.slot.status = estimate.status;
    const bool against_reference = scored_against_reference(e.name);
    parallel_for_members(
        "kushner::estimator_score", space_, members_,
        EstimatorScore<n, MemSpace>{e.slot, time.truth, against_reference ? time.reference : BankVector<MemSpace>(),
                                    against_reference ? time.reference_status : BankScalar<Status, MemSpace>(),
                                    time.truth_status, record});
  }

  void score_reference(const typename K::Slots& slots, const ScoredTime& time, bool record) {
    if (!any_filter_enabled()) return;  // the reference alone (`--filters PF`): a launch that would score nothing
    parallel_for_members(
        "kushner::filter_bank_reference_score", space_, members_,
        typename K::Reference{time.reference, time.reference_status, time.truth_status, slots, record});
  }

  template <class View>
  EnsembleMoments column_moments(const View& x, int column) const {
    return ensemble_moments(space_, Kokkos::subview(x, Kokkos::ALL, std::make_pair(column, column + 1)));
  }
  template <class View>
  Estimate mean(const View& x, int column) const {
    return mean(column_moments(x, column));
  }
  static Estimate mean(const EnsembleMoments& mo) {
    const long count = mo.members - mo.non_finite;  // over every rank
    return {mo.mean[0], count > 1 ? std::sqrt(mo.variance[0] / count) : std::nan(""), count};
  }
  /// sqrt of a mean, with the delta-method standard error se(mean) / (2 sqrt(mean)).
  template <class View>
  Estimate root_mean(const View& x, int column) const {
    return root_mean(column_moments(x, column));
  }
  static Estimate root_mean(const EnsembleMoments& mo) {
    const Estimate m = mean(mo);
    const double root = std::sqrt(m.value);
    return {root, m.standard_error / (2.0 * root), m.members};
  }

  ExecSpace space_;
  TruthModel truth_model_;
  Model filter_model_;
  long members_;
  Seed seed_;
  TruthBank<ExecSpace, TruthModel> truths_;
  BankScalar<Status, MemSpace> truth_status_;
  typename K::Slots slots_;
  ReferenceEstimator<MemSpace>* reference_ = nullptr;
  std::vector<Estimator> estimators_;
  KeptStep kept_;
  mutable DivergedMembers<MemSpace> diverged_members_;  // a segment's
  /// The buffers of an output time's reductions, kept from one output time to the next (on a GPU an allocation, and
  /// a change of the columns' addresses, waits for the device).
  struct SnapshotBuffers {
    ColumnMoments<ExecSpace> moments;
    DivergedMembers<MemSpace> diverged;
    const void* slots = nullptr;  // the slots whose columns they reduce (the bank's own or the kept ones)
  };
  struct PendingSnapshots {
    std::vector<std::string> names;
    std::vector<int> first;  // names[i]'s first column in buffers->moments
    SnapshotBuffers* buffers = nullptr;
  };
  /// Buffers free of pending snapshots that reduced the columns of `slots` before, or new ones: a set serves one
  /// `slots` for good. Step pairs' output times reduce the kept slots and the bank's own by turns, and a set taken
  /// over from the other kind uploaded its column addresses anew, each upload a wait for the device (a full queue
  /// drained at every output time, the device then idle while the host launched the next pair).
  SnapshotBuffers& free_snapshot_buffers(const void* slots) const {
    for (const auto& buffers : snapshot_buffers_) {
      const bool in_use = std::any_of(pending_.begin(), pending_.end(),
                                      [&](const PendingSnapshots& p) { return p.buffers == buffers.get(); });
      if (!in_use && buffers->slots == slots) return *buffers;
    }
    SnapshotBuffers& created = *snapshot_buffers_.emplace_back(std::make_unique<SnapshotBuffers>());
    created.slots = slots;
    return created;
  }
  mutable std::vector<std::unique_ptr<SnapshotBuffers>> snapshot_buffers_;
  // Oldest first; at most three where every step ends at an output time and pairs start one in their middle.
  mutable std::deque<PendingSnapshots> pending_;
  /// What both forms of start_segment need: per step its output's index (or -1), the snapshot columns of `names`
  /// (host form: with their places in the sink), their divergence counts, the watched elements (values not set).
  struct SegmentPlan {
    std::vector<int> output_of;
    int num_outputs = 0, last_output = -1;
    std::vector<SegmentColumn> columns;
    std::vector<int> first;  // names[i]'s first column
    NotOkMembers<MemSpace> counted;
    int num_columns = 0, width = 0, num_blocks = 0;
    WatchedElements<MemSpace> watched;
  };
  SegmentPlan plan_segment(const std::vector<char>& outputs, const std::vector<std::string>& names,
                           const std::vector<WatchedElement>& watched);
  /// Each of plan's outputs' rows (host memory: output, block, width) merged over every rank
  /// (merge_block_statistics; a collective call).
  std::vector<MergedBlocks> merge_segment_rows(const double* rows, const SegmentPlan& plan) const {
    const std::size_t output_size = static_cast<std::size_t>(plan.num_blocks) * plan.width;
    std::vector<MergedBlocks> merged;
    for (int o = 0; o < plan.num_outputs; ++o)
      merged.push_back(merge_block_statistics(rows + o * output_size, output_size, plan.num_columns,
                                              plan.counted.columns(), members_));
    return merged;
  }
  /// A started segment's outputs: merged already (with the watched values), or on their way to `sums` (rows (output,
  /// width + watched elements), host memory: the team form; on several ranks only its watched values).
  struct PendingSegment {
    std::vector<std::string> names;
    std::vector<int> first;
    int num_outputs = 0, num_columns = 0, num_counted = 0, num_watched = 0;
    std::vector<MergedBlocks> merged;
    std::vector<std::vector<double>> watched;
    Kokkos::View<const double**, Kokkos::LayoutRight, typename HostStaging<MemSpace>::space> sums;
    QueueMark<ExecSpace> copied;  // after the copy to `sums`
  };
  std::vector<PendingSegment> pending_segments_;  // oldest first, at most two (team_sums_' two halves)
  /// start_segment's forms: they step the bank and leave each output's merged moments and watched values in
  /// `pending` (the team form: on their way to the host, the moments merged there on several ranks).
  void step_host_segment(long k, double dt, const SegmentPlan& plan, PendingSegment& pending);
  void step_team_segment(long k, double dt, SegmentPlan plan, PendingSegment& pending);

  bool segment_teams_ = !host_bank;
  std::vector<double> segment_rows_;        // the host form's block statistics, kept from one segment to the next
  DeviceAddresses<MemSpace> watched_list_;  // WatchedElements::list, uploaded when it changes
  // The team form's buffers, kept from one segment to the next (on a GPU an allocation waits for the device): the
  // rows (output, block, width), their merged sums with the watched values (output, width + watched) and a host copy,
  // each in two halves (a segment's sums go to one while the host reads the segment before's from the other) with a
  // mark after each half's copy, and the columns' addresses.
  Kokkos::View<double*, MemSpace> team_rows_;
  Kokkos::View<double**, Kokkos::LayoutRight, MemSpace> team_sums_;
  Kokkos::View<double**, Kokkos::LayoutRight, typename HostStaging<MemSpace>::space> team_sums_host_;
  QueueMark<ExecSpace> team_sums_copied_[2];
  int team_sums_half_ = 0;  // the half the next segment's sums go to
  DeviceAddresses<MemSpace> team_columns_;
};

template <class ExecSpace, class Model, class TruthModel>
FilterBank<ExecSpace, Model, TruthModel>::FilterBank(const ExecSpace& space, const TruthModel& truth_model,
                                                     const Model& filter_model, long members, Seed seed,
                                                     const std::vector<std::string>& filters,
                                                     const OptionValues& options, const PreparedFilters& prepared)
    : space_(space),
      truth_model_(truth_model),
      filter_model_(filter_model),
      members_(members),
      seed_(seed),
      truths_(space, truth_model, members, seed),
      truth_status_("kushner::truth_status", members) {
  for (const auto& name : filters)
    KUSHNER_REQUIRE(enable_named_filter_slot(slots_, name, filter_model, members, options, prepared, seed),
                    "filter '" << name << "' is not supported by model " << Model::name);
  parallel_for_members("kushner::filter_bank_initial_score", space_, members_,
                       typename K::Initial{truths_.state(), slots_});
}

template <class ExecSpace, class Model, class TruthModel>
void FilterBank<ExecSpace, Model, TruthModel>::set_reference(ReferenceEstimator<MemSpace>* reference) {
  reference_ = reference;
  if (reference_) score_reference(slots_, now(), true);
}

template <class ExecSpace, class Model, class TruthModel>
void FilterBank<ExecSpace, Model, TruthModel>::add_estimator(ReferenceEstimator<MemSpace>* estimator) {
  KUSHNER_REQUIRE(estimator != nullptr, "add_estimator: null estimator");
  Estimator e;
  e.estimator = estimator;
  e.name = estimator->name();
  e.slot.enabled = true;
  e.slot.score = BankVector<MemSpace>("kushner::score_" + e.name, members_, num_score_columns);
  e.slot.snapshot = BankVector<MemSpace>("kushner::snapshot_" + e.name, members_, num_snapshot_columns);
  estimators_.push_back(e);
  score_estimator(estimators_.back(), estimator->estimate(), now(), true);
}

template <class ExecSpace, class Model, class TruthModel>
void FilterBank<ExecSpace, Model, TruthModel>::step(long k, double dt, bool record) {
  run_step_kernel(k, dt, record);
  bool reference_stepped = false;
  for (auto& e : estimators_) {
    e.estimator->advance(k, k * dt, dt, truths_.observations());
    reference_stepped = reference_stepped || e.estimator == reference_;
  }
  if (reference_ && !reference_stepped) reference_->advance(k, k * dt, dt, truths_.observations());
  score_now(record);
}

template <class ExecSpace, class Model, class TruthModel>
void FilterBank<ExecSpace, Model, TruthModel>::step_pair(long k, double dt, bool record,
                                                         const std::vector<std::string>* first_output) {
  KUSHNER_REQUIRE(steps_in_pairs(), "step_pair: the reference does not advance in pairs");
  const bool record_first = first_output != nullptr;
  run_step_kernel(k, dt, record_first);
  keep_step(record_first);
  run_step_kernel(k + 1, dt, record);
  reference_->advance_pair(k, k * dt, dt, kept_.dy, truths_.observations());
  const EstimateViews<MemSpace> reference_then = reference_->first_of_pair();
  const ScoredTime then{kept_.truth, kept_.truth_status, reference_then.mean, reference_then.status};
  for (auto& e : estimators_)
    if (e.estimator != reference_) e.estimator->advance(k, k * dt, dt, kept_.dy);
  score_reference(kept_.slots, then, record_first);
  for (auto& e : estimators_)
    score_estimator(e, e.estimator == reference_ ? reference_then : e.estimator->estimate(), then, record_first);
  // Queued before step k + 1's scores overwrite the estimators' snapshot columns (the bank's are kept).
  if (record_first) start_snapshots_of(*first_output, kept_.slots, kept_.truth_status);
  for (auto& e : estimators_)
    if (e.estimator != reference_) e.estimator->advance(k + 1, (k + 1) * dt, dt, truths_.observations());
  score_now(record);
}

template <class ExecSpace, class Model, class TruthModel>
std::vector<char> FilterBank<ExecSpace, Model, TruthModel>::members_ok(const std::string& name) const {
  std::vector<char> ok(members_, 0);
  space_.fence();
  const auto truth_status = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), truth_status_);
  with_slot(name, [&](const auto& slot) {
    const auto status = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), slot.status);
    for (long member = 0; member < members_; ++member)
      ok[member] = status(member) == Status::ok && truth_status(member) == Status::ok;
  });
  return ok;
}

template <class ExecSpace, class Model, class TruthModel>
void FilterBank<ExecSpace, Model, TruthModel>::start_snapshots(const std::vector<std::string>& names) const {
  start_snapshots_of(names, slots_, truth_status_);
}

template <class ExecSpace, class Model, class TruthModel>
void FilterBank<ExecSpace, Model, TruthModel>::start_snapshots_of(
    const std::vector<std::string>& names, const typename K::Slots& slots,
    const BankScalar<Status, MemSpace>& truth_status) const {
  std::vector<typename ColumnMoments<ExecSpace>::Column> columns;
  std::vector<BankScalar<Status, MemSpace>> statuses;
  PendingSnapshots pending;
  pending.names = names;
  for (const auto& name : names)
    with_slot_in(slots, name, [&](const auto& slot) {
      pending.first.push_back(static_cast<int>(columns.size()));
      columns.push_back(Kokkos::subview(slot.snapshot, Kokkos::ALL, int(snapshot_squared_error)));
      columns.push_back(Kokkos::subview(slot.snapshot, Kokkos::ALL, int(snapshot_nees)));
      if (scored_against_reference(name))
        columns.push_back(Kokkos::subview(slot.snapshot, Kokkos::ALL, int(snapshot_reference_squared_error)));
      statuses.push_back(slot.status);
    });
  pending.buffers = &free_snapshot_buffers(&slots);
  pending.buffers->moments.start(space_, columns, pending.buffers->diverged(space_, statuses, truth_status));
  pending_.push_back(std::move(pending));
}

template <class ExecSpace, class Model, class TruthModel>
std::vector<FilterSnapshot> FilterBank<ExecSpace, Model, TruthModel>::finish_snapshots() const {
  KUSHNER_REQUIRE(!pending_.empty(), "finish_snapshots: no snapshots started");
  const PendingSnapshots pending = std::move(pending_.front());
  pending_.pop_front();
  return snapshots_of(pending.buffers->moments.finish(), pending.names, pending.first);
}

template <class ExecSpace, class Model, class TruthModel>
std::vector<FilterSnapshot> FilterBank<ExecSpace, Model, TruthModel>::snapshots_of(
    const MergedBlocks& merged, const std::vector<std::string>& names, const std::vector<int>& first) const {
  const std::vector<EnsembleMoments>& moments = merged.moments;
  const std::vector<long>& diverged = merged.counts;  // per filter of names
  std::vector<FilterSnapshot> result;
  for (std::size_t i = 0; i < names.size(); ++i) {
    FilterSnapshot s;
    const Estimate rmse = root_mean(moments[first[i]]);
    const Estimate nees = mean(moments[first[i] + 1]);
    const Estimate ref =
        scored_against_reference(names[i]) ? root_mean(moments[first[i] + 2]) : Estimate{std::nan(""), std::nan(""), 0};
    s.rmse_truth = rmse.value;
    s.rmse_truth_se = rmse.standard_error;
    s.nees = nees.value;
    s.nees_se = nees.standard_error;
    s.rmse_ref = ref.value;
    s.rmse_ref_se = ref.standard_error;
    s.diverged = diverged[i];
    result.push_back(s);
  }
  return result;
}

template <class ExecSpace, class Model, class TruthModel>
void FilterBank<ExecSpace, Model, TruthModel>::start_segment(const long k, const double dt,
                                                             const std::vector<char>& outputs,
                                                             const std::vector<std::string>& names,
                                                             const std::vector<WatchedElement>& watched) {
  KUSHNER_REQUIRE(steps_in_segments(), "start_segment: estimators step beside the bank");
  KUSHNER_REQUIRE(pending_segments_.size() < 2, "start_segment: two segments started and not finished");
  const SegmentPlan plan = plan_segment(outputs, names, watched);
  PendingSegment pending;
  pending.names = names;
  pending.first = plan.first;
  pending.num_outputs = plan.num_outputs;
  pending.num_columns = plan.num_columns;
  pending.num_counted = plan.counted.columns();
  pending.num_watched = plan.watched.count;
  if (segment_teams_)
    step_team_segment(k, dt, plan, pending);
  else
    step_host_segment(k, dt, plan, pending);
  pending_segments_.push_back(std::move(pending));
}

template <class ExecSpace, class Model, class TruthModel>
std::vector<typename FilterBank<ExecSpace, Model, TruthModel>::SegmentOutput>
FilterBank<ExecSpace, Model, TruthModel>::finish_segment() {
  KUSHNER_REQUIRE(!pending_segments_.empty(), "finish_segment: no segment started");
  PendingSegment pending = std::move(pending_segments_.front());
  pending_segments_.erase(pending_segments_.begin());
  if (pending.sums.data() != nullptr) {
    pending.copied.wait();
    const bool merged = !pending.merged.empty();  // on several ranks, merged as the segment was taken
    const int width = 3 * pending.num_columns + pending.num_counted;
    for (int o = 0; o < pending.num_outputs; ++o) {
      const double* const row = &pending.sums(o, 0);
      if (!merged) pending.merged.push_back(merged_blocks(row, pending.num_columns, pending.num_counted, members_));
      pending.watched.emplace_back(row + width, row + width + pending.num_watched);
    }
  }
  std::vector<SegmentOutput> result;
  for (int o = 0; o < pending.num_outputs; ++o)
    result.push_back({snapshots_of(pending.merged[o], pending.names, pending.first), std::move(pending.watched[o])});
  return result;
}

template <class ExecSpace, class Model, class TruthModel>
typename FilterBank<ExecSpace, Model, TruthModel>::SegmentPlan FilterBank<ExecSpace, Model, TruthModel>::plan_segment(
    const std::vector<char>& outputs, const std::vector<std::string>& names,
    const std::vector<WatchedElement>& watched) {
  using Step = typename K::Step;
  SegmentPlan plan;
  const int steps = static_cast<int>(outputs.size());
  plan.output_of.assign(steps, -1);
  for (int s = 0; s < steps; ++s)
    if (outputs[s]) {
      plan.output_of[s] = plan.num_outputs++;
      plan.last_output = s;
    }
  // start_snapshots' columns (no reference here: two per filter) and counts.
  std::vector<BankScalar<Status, MemSpace>> statuses;
  for (const auto& name : names) {
    bool found = false;
    for_each_filter_slot(slots_, [&](const auto& slot) {
      using Filter = decltype(slot.filter);
      if (!slot.enabled || name != Filter::name) return;
      found = true;
      plan.first.push_back(static_cast<int>(plan.columns.size()));
      const int sink = Step::template fills_sink<Filter>() ? 2 * Step::template slot_index<Filter>() : -1;
      double* const snapshot = slot.snapshot.data();
      const std::size_t stride = slot.snapshot.stride(1);
      plan.columns.push_back({snapshot + snapshot_squared_error * stride, sink});
      plan.columns.push_back({snapshot + snapshot_nees * stride, sink < 0 ? -1 : sink + 1});
      statuses.push_back(slot.status);
    });
    KUSHNER_REQUIRE(found, "filter '" << name << "' is not in this bank");
  }
  plan.counted = diverged_members_(space_, statuses, truth_status_);
  plan.num_columns = static_cast<int>(plan.columns.size());
  plan.width = 3 * plan.num_columns + plan.counted.columns();
  plan.num_blocks = static_cast<int>(moment_blocks(members_));
  for (const WatchedElement& e : watched)
    KUSHNER_REQUIRE(e.member >= 0 && e.member < members_,
                    "start_segment: watched member " << e.member << " not in the bank");
  plan.watched.list = watched_list_.update(space_, WatchedElements<MemSpace>::list_of(watched));
  plan.watched.count = static_cast<int>(watched.size());
  return plan;
}

template <class ExecSpace, class Model, class TruthModel>
void FilterBank<ExecSpace, Model, TruthModel>::step_host_segment(const long k, const double dt, const SegmentPlan& plan,
                                                                 PendingSegment& pending) {
  if constexpr (host_bank) {
    const int steps = static_cast<int>(plan.output_of.size());
    const std::size_t output_size = static_cast<std::size_t>(plan.num_blocks) * plan.width;
    segment_rows_.resize(output_size * plan.num_outputs);
    WatchedElements<Kokkos::HostSpace> watched{plan.watched.list, plan.watched.count, {}, 0};
    watched.values = Kokkos::View<double**, Kokkos::LayoutRight, Kokkos::HostSpace>(
        Kokkos::view_alloc(Kokkos::WithoutInitializing, "kushner::segment_watched"), plan.num_outputs, watched.count);
    const FilterBankSegment<typename K::Step, NotOkMembers<MemSpace>> segment{step_kernel(k, dt, false),
                                                                              k,
                                                                              steps,
                                                                              dt,
                                                                              plan.output_of.data(),
                                                                              plan.last_output,
                                                                              plan.columns.data(),
                                                                              plan.num_columns,
                                                                              plan.counted,
                                                                              segment_rows_.data(),
                                                                              plan.num_blocks,
                                                                              plan.width,
                                                                              static_cast<int>(members_),
                                                                              watched};
    space_.fence();
    // Blocks handed out as threads free up: a thread slowed by anything else on its core no longer holds the others
    // at the end of the segment (the rows are merged in block order, so the bits do not depend on who ran what).
    Kokkos::parallel_for("kushner::filter_bank_segment",
                         Kokkos::RangePolicy<ExecSpace, Kokkos::Schedule<Kokkos::Dynamic>>(space_, 0, plan.num_blocks),
                         segment);
    space_.fence();
    pending.merged = merge_segment_rows(segment_rows_.data(), plan);
    for (int o = 0; o < plan.num_outputs; ++o) {
      const double* const values = watched.values.data() + static_cast<std::size_t>(o) * watched.count;
      pending.watched.emplace_back(values, values + watched.count);
    }
  }
}

template <class ExecSpace, class Model, class TruthModel>
void FilterBank<ExecSpace, Model, TruthModel>::step_team_segment(const long k, const double dt, SegmentPlan plan,
                                                                 PendingSegment& pending) {
  using Segment = FilterBankTeamSegment<typename K::Step, NotOkMembers<MemSpace>, MemSpace>;
  const int steps = static_cast<int>(plan.output_of.size());
  KUSHNER_REQUIRE(steps <= team_segment_max_steps,
                  "start_segment: " << steps << " steps, more than a segment's " << team_segment_max_steps);
  const int num_outputs = plan.num_outputs, width = plan.width, num_blocks = plan.num_blocks;
  const std::size_t output_size = static_cast<std::size_t>(num_blocks) * width;
  if (team_rows_.extent(0) < output_size * num_outputs)
    team_rows_ = Kokkos::View<double*, MemSpace>(
        Kokkos::view_alloc(space_, Kokkos::WithoutInitializing, "kushner::segment_rows"), output_size * num_outputs);
  // The outputs' merged sums and watched values: to one half of team_sums_ (room for a segment of every step an
  // output), while the host may still read the segment before's from the other.
  const int half = team_sums_half_;
  const auto half_rows = std::make_pair(half * team_segment_max_steps, (half + 1) * team_segment_max_steps);
  if (num_outputs > 0) {
    team_sums_half_ = 1 - team_sums_half_;
    if (team_sums_.extent(1) != static_cast<std::size_t>(width + plan.watched.count)) {
      // (A segment still waiting to be finished keeps its half of the old host copy: PendingSegment::sums.)
      team_sums_ = Kokkos::View<double**, Kokkos::LayoutRight, MemSpace>(
          Kokkos::view_alloc(space_, Kokkos::WithoutInitializing, "kushner::segment_sums"), 2 * team_segment_max_steps,
          width + plan.watched.count);
      team_sums_host_ = Kokkos::create_mirror_view(typename HostStaging<MemSpace>::space(), team_sums_);
    }
    plan.watched.values = Kokkos::subview(team_sums_, half_rows, Kokkos::ALL);
    plan.watched.first_column = width;
  }
  std::vector<std::uintptr_t> addresses;
  for (const SegmentColumn& column : plan.columns) addresses.push_back(reinterpret_cast<std::uintptr_t>(column.column));
  Segment segment{step_kernel(k, dt, false),
                  k,
                  steps,
                  dt,
                  {},
                  plan.last_output,
                  {team_columns_.update(space_, addresses)},
                  plan.num_columns,
                  0,
                  plan.counted,
                  team_rows_,
                  num_blocks,
                  width,
                  static_cast<int>(members_),
                  plan.watched};
  for (int s = 0; s < team_segment_max_steps; ++s) segment.output_of[s] = s < steps ? plan.output_of[s] : -1;
  if constexpr (!host_bank) {
    // The columns a GPU's team keeps in its block's sink: those the host's segments keep in theirs (SegmentColumn::
    // sink), at their own column's place; each filter's slot in the launch's kernel learns where its pair starts.
    for_each_filter_slot(segment.first.slots, [&](auto& slot) {
      if (!slot.enabled) return;
      const double* const squared_error = slot.snapshot.data() + snapshot_squared_error * slot.snapshot.stride(1);
      for (int c = 0; c + 1 < plan.num_columns; ++c)
        if (plan.columns[c].column == squared_error && plan.columns[c].sink >= 0) {
          KUSHNER_REQUIRE(c + 1 < 64, "start_segment: " << plan.num_columns << " columns, more than a sink's 64");
          slot.team_sink = c * moment_block_size;
          segment.sink_mask |= std::uint64_t{3} << c;
        }
    });
  }
  const auto scratch = Kokkos::PerTeam(segment.scratch_bytes());
  if constexpr (host_bank) {  // one thread per team (team_block_statistic's form)
    Kokkos::parallel_for("kushner::filter_bank_team_segment",
                         Kokkos::TeamPolicy<ExecSpace>(space_, num_blocks, 1).set_scratch_size(0, scratch), segment);
  } else {  // a thread per member, as many as the step's registers let one CUDA block hold, in whole warps
    // Bounds of 3 blocks of 256 per SM (80 registers on sm_90, some spilled, where the step took 120-128 and 2
    // blocks fit) gave 1.14-1.27x the segments' rate on an H200 (perf/filter_bank.md); 4 blocks spilled more.
    using Policy = Kokkos::TeamPolicy<ExecSpace, Kokkos::LaunchBounds<moment_block_size, 3>>;
    auto probe = Policy(space_, num_blocks, Kokkos::AUTO);
    probe.set_scratch_size(0, scratch);
    const int most = probe.team_size_max(segment, Kokkos::ParallelForTag());
    const int team_size = std::max(moment_lanes, std::min(moment_block_size, most) / moment_lanes * moment_lanes);
    auto policy = Policy(space_, num_blocks, team_size);
    policy.set_scratch_size(0, scratch);
    Kokkos::parallel_for("kushner::filter_bank_team_segment", policy, segment);
#if defined(KOKKOS_ENABLE_CUDA) && KOKKOS_VERSION < 40000
    // Kokkos 3 launches a TeamPolicy kernel with cudaFuncCachePreferShared at its first launch (kokkos#2066, and
    // only then: configure_shmem_preference): the shared memory for the block sinks of 3 blocks, and the rest L1,
    // from the next launch on. On an H200 (1e6 members, four filters) the sink with Kokkos' carveout made steps
    // without outputs x0.89; with this x1.02-1.03, and output steps x1.15-1.18 (perf/filter_bank.md). Set when
    // it changes; the device's shared memory per SM asked once.
    if constexpr (std::is_same<ExecSpace, Kokkos::Cuda>::value) {
      using Driver = Kokkos::Impl::ParallelFor<Segment, Policy, Kokkos::Cuda>;
      static int per_sm = -1, carveout = -1;  // per kernel (this function's instance); one device per process
      if (per_sm < 0) {
        int device = 0;
        per_sm = 0;
        cudaGetDevice(&device);
        cudaDeviceGetAttribute(&per_sm, cudaDevAttrMaxSharedMemoryPerMultiprocessor, device);
      }
      const double block_bytes = segment.scratch_bytes() + sizeof(double) * (team_size + 2) + 1024;  // + reserved
      const int percent = per_sm > 0 ? std::min(100, static_cast<int>(std::ceil(300.0 * block_bytes / per_sm))) : 100;
      if (percent != carveout) {
        const auto kernel = Kokkos::Impl::CudaParallelLaunch<Driver, typename Policy::launch_bounds>::get_kernel_func();
        KUSHNER_REQUIRE(
            cudaFuncSetAttribute(kernel, cudaFuncAttributePreferredSharedMemoryCarveout, percent) == cudaSuccess,
            "start_segment: cudaFuncSetAttribute (shared memory carveout) failed");
        carveout = percent;
      }
    }
#endif
  }
  if (num_outputs == 0) return;
  const auto sums = Kokkos::subview(team_sums_, half_rows, Kokkos::ALL);
  if (collective::ranks() > 1) {  // every rank's rows, gathered in rank order (the same branch on every rank)
    const auto rows = Kokkos::create_mirror_view_and_copy(
        Kokkos::HostSpace(), Kokkos::subview(team_rows_, std::make_pair(std::size_t(0), output_size * num_outputs)));
    pending.merged = merge_segment_rows(rows.data(), plan);
  } else {
    merge_block_rows(space_,
                     MergeBlockRows<MemSpace>{team_rows_, num_blocks, plan.num_columns, plan.counted.columns(), sums},
                     num_outputs);
  }
  const auto host_sums = Kokkos::subview(team_sums_host_, half_rows, Kokkos::ALL);
  if (team_sums_host_.data() != team_sums_.data()) Kokkos::deep_copy(space_, host_sums, sums);
  pending.sums = host_sums;
  team_sums_copied_[half].record(space_);
  pending.copied = team_sums_copied_[half];  // a copy of the mark: the same event
}

template <class ExecSpace, class Model, class TruthModel>
FilterScores FilterBank<ExecSpace, Model, TruthModel>::scores(const std::string& name, long points) const {
  FilterScores s;
  with_slot(name, [&](const auto& slot) {
    BankVector<MemSpace> per_member("kushner::member_scores", members_, num_member_score_columns);
    parallel_for_members("kushner::member_scores", space_, members_,
                         MemberScores<MemSpace>{slot.score, slot.status, truth_status_, per_member,
                                                static_cast<double>(points), scored_against_reference(name),
                                                reference_ ? reference_->status() : BankScalar<Status, MemSpace>()});
    s.rmse_truth = root_mean(per_member, member_mean_squared_error);
    s.nees = mean(per_member, member_mean_nees);
    s.rmse_ref = root_mean(per_member, member_mean_squared_reference_error);
    s.not_positive_definite = count_status(space_, slot.status, Status::not_positive_definite, truth_status_);
    s.non_finite = count_status(space_, slot.status, Status::non_finite, truth_status_);
    s.diverged = s.not_positive_definite + s.non_finite;
  });
  return s;
}

template <class ExecSpace, class Model, class TruthModel>
void FilterBank<ExecSpace, Model, TruthModel>::visit_state(StateArchive& archive) {
  archive.scope = "truth.";
  archive.view("x", truths_.state());
  archive.view("observations", truths_.observations());
  archive.view("status", truth_status_);
  for_each_filter_slot(slots_, [&](auto& slot) {
    using Filter = decltype(slot.filter);
    if (!slot.enabled) return;
    archive.scope = std::string(Filter::name) + ".";
    archive.view("m", slot.m);
    archive.view("P", slot.P);
    archive.view("status", slot.status);
    archive.view("score", slot.score);
    archive.view("snapshot", slot.snapshot);
    if constexpr (detail::has_own_state<Filter, StateArchive>::value) slot.filter.visit_state(archive);
  });
  for (auto& e : estimators_) {
    archive.scope = e.name + ".";
    archive.view("score", e.slot.score);
    archive.view("snapshot", e.slot.snapshot);
  }
  archive.scope.clear();
}

template <class ExecSpace, class Model, class TruthModel>
long FilterBank<ExecSpace, Model, TruthModel>::truths_escaped() const {
  return count_status(space_, truth_status_, Status::non_finite);
}

#define KUSHNER_SHARED_INSTANCE(Space, Model) extern template class FilterBank<Space, Model>;
KUSHNER_FOR_EACH_SHARED_INSTANCE
#undef KUSHNER_SHARED_INSTANCE

}  // namespace kushner
