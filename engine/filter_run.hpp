#pragma once
// A whole filter run over a time grid: the bank of truths and filters stepped from 0 to T, metrics collected
// at the grid's output times and over the run. A filter that needs a pass over the whole horizon first (ASRE
// iterates until its estimate trajectory settles) gets its pre-pass here, through its own `prepare`
// (kernels/filters/filter_protocol.hpp); the main pass then runs what it prepared. The particle filter (PF) and
// the exact or grid filter (EXACT) run beside the bank when named among the filters; the particle filter (else
// the exact filter) is then the reference of rmse_ref. Shared by `kushner filter`, `kushner compare`, the tests
// and the benchmarks.
#include "core/fields.hpp"
#include "core/options.hpp"
#include "engine/exact_reference_estimator.hpp"
#include "engine/filter_bank.hpp"
#include "engine/member_share.hpp"
#include "engine/particle_reference.hpp"
#include "engine/progress_callback.hpp"
#include "engine/run_checkpointing.hpp"
#include "engine/state_archive.hpp"
#include "engine/time_grid.hpp"

#include <Kokkos_Core.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace kushner {

struct FilterReport {
  std::vector<std::string> filters;                 // report order
  std::vector<double> times;                        // output times
  std::vector<std::vector<FilterSnapshot>> series;  // [time][filter]
  std::vector<FilterScores> scores;                 // [filter], over the whole run
  long truths_escaped = 0;                          // members left out of every metric
  bool has_reference = false;
  std::string reference;                        // the reference's name (PF, EXACT) when has_reference
  std::map<std::string, Fields> filter_fields;  // bank filter -> what it adds to its summary
  std::map<std::string, Fields> estimators;     // estimator beside the bank -> its describe()
  double step_loop_seconds = 0.0;               // wall time of the main pass's steps (this rank; fenced)
  long steps_run = 0;                           // steps of the main pass this process ran (fewer when resumed)
};

/// `observe` is called at t = 0 and at every output time, in order, with the bank and the outside estimators (PF,
/// EXACT), e.g. to record chosen members' trajectories. `values` null: the bank is at t. Otherwise the bank may be
/// further on, and `values` are the values at t of the elements `elements` named (in their order): a run without
/// outside estimators takes several steps at a time (FilterBank::start_segment), which copy those elements at each
/// output step. Without `elements`, such a run takes its steps one at a time.
template <class ExecSpace, class Model, class TruthModel = Model>
struct OutputObserver {
  using Bank = FilterBank<ExecSpace, Model, TruthModel>;
  std::function<void(double t, const Bank&,
                     const std::vector<const ReferenceEstimator<typename ExecSpace::memory_space>*>&,
                     const std::vector<double>* values)>
      observe;
  /// The elements of this rank's bank observe reads (the same at every output time, with no outside estimators).
  std::function<std::vector<WatchedElement>(const Bank&)> elements;
};

/// Fewest members (of all ranks) for which a run takes its steps in segments: below it the blocks of
/// moment_block_size members are too few to share among a host's threads, and one step at a time costs little.
constexpr long segment_min_members = 16 * moment_block_size;

/// Estimators a caller adds beside the bank (e.g. `kushner reproduce`'s exact quadrature for a deterministic
/// model, or a paper's printed variant of a filter); run_filters owns them from then on.
template <class ExecSpace>
using ExtraEstimators = std::vector<std::unique_ptr<ReferenceEstimator<typename ExecSpace::memory_space>>>;

/// Steps a run of `filters` reports to its progress callback: the main pass and every pre-pass.
template <class Model>
long progress_steps(const std::vector<std::string>& filters, const TimeGrid& grid) {
  long passes = 1;
  for_each_filter_type<Model, Kokkos::HostSpace>([&](auto* tag) {
    using Filter = std::remove_pointer_t<decltype(tag)>;
    if (std::find(filters.begin(), filters.end(), Filter::name) != filters.end())
      passes += filter_prepass_passes<Filter>();
  });
  return passes * grid.steps;
}

namespace detail {

/// The pre-passes of the selected filters that have one, in report order: each filter's prepare() runs the
/// truths with that filter alone as often as it needs. `progress_base` advances by each filter's declared
/// passes.
template <class ExecSpace, class Model, class TruthModel>
typename FilterBank<ExecSpace, Model, TruthModel>::PreparedFilters prepare_filters(
    const ExecSpace& space, const TruthModel& truth_model, const Model& filter_model, long members, Seed seed,
    const TimeGrid& grid, const std::vector<std::string>& filters, const OptionValues& options,
    const ProgressCallback& progress, long& progress_base) {
  using Bank = FilterBank<ExecSpace, Model, TruthModel>;
  using MemSpace = typename ExecSpace::memory_space;
  typename Bank::PreparedFilters prepared;
  kushner::for_each_filter_type<Model, MemSpace>([&](auto* tag) {
    using Filter = std::remove_pointer_t<decltype(tag)>;
    if constexpr (Filter::unsupported == nullptr && filter_prepass_passes<Filter>() > 0) {
      if (std::find(filters.begin(), filters.end(), Filter::name) == filters.end()) return;
      const long start = progress_base;
      const auto run_alone = [&](const Filter& filter) {
        typename Bank::PreparedFilters only;
        std::get<std::optional<Filter>>(only) = filter;
        Bank bank(space, truth_model, filter_model, members, seed, {Filter::name}, options, only);
        for (long k = 0; k < grid.steps; ++k) {
          bank.step(k, grid.dt, false);
          if (progress) progress(progress_base + k + 1);
        }
        progress_base += grid.steps;
        return bank.members_ok(Filter::name);
      };
      std::get<std::optional<Filter>>(prepared) =
          Filter::prepare(options.with_defaults(filter_options<Filter>()), filter_model, members, run_alone);
      progress_base = start + filter_prepass_passes<Filter>() * grid.steps;
    }
  });
  return prepared;
}

}  // namespace detail

/// Runs the filters `filters` (bank filters the model supports, then PF and/or EXACT: drivers/filter_selection.hpp)
/// over `grid` with the filters' settings `options`, and the `extra` estimators after them (reported after
/// them, in their order). The truths follow truth_model, the filters filter_model. With PF, EXACT or an extra
/// estimator, every other estimate is also scored against the reference's mean (rmse_ref): the first of PF,
/// EXACT, extra[0], ... `progress` counts the steps of all passes (progress_steps).
///
/// `members` is the whole ensemble: in a run over MPI ranks each rank runs its share (engine/member_share.hpp),
/// and the report, the same on every rank, covers all members. `observer` sees this rank's bank.
///
/// `checkpointing` (engine/run_checkpointing.hpp): with a writer, the state after a step (the report so far,
/// the bank, the outside estimators, the caller's part) is saved when its clock says so and when SIGINT or
/// SIGTERM came (then RunInterrupted is thrown); with `resume`, the run continues from such a state. Pre-passes
/// run again on resuming (they are deterministic).
template <class ExecSpace, class Model, class TruthModel>
FilterReport run_filters(const ExecSpace& space, const TruthModel& truth_model, const Model& filter_model, long members,
                         std::uint32_t seed, const TimeGrid& grid, const std::vector<std::string>& filters,
                         const OptionValues& options = {}, const ParticleSettings& particle = {},
                         const ProgressCallback& progress = {},
                         const OutputObserver<ExecSpace, Model, TruthModel>& observer = {},
                         ExtraEstimators<ExecSpace> extra = {}, const RunCheckpointing& checkpointing = {}) {
  using MemSpace = typename ExecSpace::memory_space;
  const MemberShare share = member_share(members);
  const Seed rank_seed = share.seed(seed);
  members = share.count;
  FilterReport report;
  report.filters = filters;
  std::vector<std::string> bank_filters;
  std::vector<std::unique_ptr<ReferenceEstimator<MemSpace>>> outside;
  for (const auto& name : filters) {
    if (!is_outside_estimator(name)) {
      bank_filters.push_back(name);
    } else if (name == particle_filter_name) {
      if constexpr (particle_filter_unsupported<Model>() == nullptr)
        outside.push_back(make_particle_reference(space, filter_model, members, rank_seed, particle));
    } else if constexpr (has_exact_reference<Model>) {
      outside.push_back(std::make_unique<ExactReferenceEstimator<ExecSpace, Model>>(space, filter_model, members));
    }
  }
  KUSHNER_REQUIRE(bank_filters.size() + outside.size() == filters.size(),
                  "run_filters: PF or EXACT named for a model that has none (select_estimators refuses it)");
  for (auto& e : extra) {
    KUSHNER_REQUIRE(e && std::find(filters.begin(), filters.end(), e->name()) == filters.end(),
                    "run_filters: an extra estimator is null or named like a selected one");
    report.filters.push_back(e->name());
    outside.push_back(std::move(e));
  }
  long progress_base = 0;
  const auto prepared = detail::prepare_filters(space, truth_model, filter_model, members, rank_seed, grid,
                                                bank_filters, options, progress, progress_base);
  FilterBank<ExecSpace, Model, TruthModel> bank(space, truth_model, filter_model, members, rank_seed, bank_filters,
                                                options, prepared);
  std::vector<const ReferenceEstimator<MemSpace>*> outside_view;
  if (!outside.empty()) {
    bank.set_reference(outside.front().get());  // PF comes before EXACT
    report.has_reference = true;
    report.reference = outside.front()->name();
  }
  for (auto& e : outside) {
    bank.add_estimator(e.get());
    outside_view.push_back(e.get());
  }
  // An output time's metrics are queued when the bank reaches it and collected once the next step is queued (or
  // before a checkpoint, or at the end): on a GPU the host merges them while the device takes that step. A segment's
  // likewise, once the next segment is queued (FilterBank::start_segment).
  int collecting = 0;  // output times whose metrics are queued, not yet collected
  const auto record = [&](double t) {
    report.times.push_back(t);
    bank.start_snapshots(report.filters);
    ++collecting;
    if (observer.observe) observer.observe(t, bank, outside_view, nullptr);
  };
  struct StartedSegment {
    long k;
    std::vector<char> outputs;
  };
  std::vector<StartedSegment> started_segments;  // oldest first
  const auto collect_segment = [&] {
    const StartedSegment segment = started_segments.front();
    started_segments.erase(started_segments.begin());
    const auto series = bank.finish_segment();
    for (long s = 0, o = 0; s < static_cast<long>(segment.outputs.size()); ++s)
      if (segment.outputs[s]) {
        const double t = (segment.k + s + 1) * grid.dt;
        report.times.push_back(t);
        report.series.push_back(series[o].snapshots);
        if (observer.observe) observer.observe(t, bank, outside_view, &series[o].watched);
        ++o;
      }
  };
  const auto collect_oldest = [&](int count) {  // the `count` oldest queued output times
    for (; count > 0; --count, --collecting) report.series.push_back(bank.finish_snapshots());
  };
  const auto collect_step = [&] { collect_oldest(collecting); };
  const auto collect = [&] {
    collect_step();
    while (!started_segments.empty()) collect_segment();
  };
  // Everything that carries from one step to the next, in a fixed order; `step`: the steps taken.
  const auto visit_run_state = [&](StateArchive& archive, long& step) {
    archive.value("step", step);
    if (checkpointing.visit_caller_state) checkpointing.visit_caller_state(archive);
    archive.values("report.times", report.times);
    std::vector<FilterSnapshot> series;
    for (const auto& row : report.series) series.insert(series.end(), row.begin(), row.end());
    archive.values("report.series", series);
    if (archive.loading()) {
      KUSHNER_INPUT_REQUIRE(
          series.size() == report.times.size() * report.filters.size() && step >= 0 && step <= grid.steps,
          "checkpoint: its report does not fit this run: written for another option set");
      report.series.clear();
      for (std::size_t r = 0; r < report.times.size(); ++r)
        report.series.emplace_back(series.begin() + r * report.filters.size(),
                                   series.begin() + (r + 1) * report.filters.size());
    }
    bank.visit_state(archive);
    for (auto& e : outside) {
      archive.scope = e->name() + ".";
      e->visit_state(archive);
    }
    archive.scope.clear();
    archive.finish();
  };
  long first_step = 0;
  if (checkpointing.resume) {
    StateArchive archive(*checkpointing.resume);
    visit_run_state(archive, first_step);
  } else {
    record(0.0);
  }
  CheckpointClock clock(checkpointing.every_seconds);
  const auto save = [&](long step) {
    collect();
    StateArchive archive;
    visit_run_state(archive, step);
    checkpointing.write(archive.bytes(), step, grid.steps);
    clock.restart();
  };
  std::size_t next_output =
      std::upper_bound(grid.output_steps.begin(), grid.output_steps.end(), first_step) - grid.output_steps.begin();
  space.fence();
  const auto loop_start = std::chrono::steady_clock::now();
  const auto ends_at_output = [&](long step) {
    return next_output < grid.output_steps.size() && grid.output_steps[next_output] == step;
  };
  // Several steps at a time where nothing steps beside the bank (FilterBank::start_segment): on the host they doubled
  // the bank's rate, on a GPU 1.7-1.8x (perf/filter_bank.md). The same on every rank (the total member count), as
  // every rank must make the same collective calls.
  const bool segments =
      bank.steps_in_segments() && share.total >= segment_min_members && (!observer.observe || observer.elements);
  const std::vector<WatchedElement> watched =
      segments && observer.observe ? observer.elements(bank) : std::vector<WatchedElement>{};
  const auto take_segment = [&](const long k) {
    collect_step();  // the output at t = 0
    const long steps = std::min<long>(FilterBank<ExecSpace, Model, TruthModel>::segment_steps, grid.steps - k);
    std::vector<char> outputs;
    for (long s = 0; s < steps; ++s) {
      outputs.push_back(ends_at_output(k + s + 1));
      if (outputs.back()) ++next_output;
    }
    bank.start_segment(k, grid.dt, outputs, report.filters, watched);
    started_segments.push_back({k, std::move(outputs)});
    if (started_segments.size() > 1) collect_segment();  // the one before: merged while this one runs
    return k + steps;
  };
  for (long k = first_step; k < grid.steps;) {
    if (segments) {
      k = take_segment(k);
    } else {
      // Two steps at a time where the reference takes them in one pass (FilterBank::step_pair), unless the first is
      // the last, or ends at an output time where an observer reads the bank (it would be a step further on).
      const bool first_output = ends_at_output(k + 1);
      const bool pair = bank.steps_in_pairs() && !(first_output && observer.observe) && k + 2 <= grid.steps;
      const int queued_before = collecting;
      if (pair && first_output) {  // its metrics are queued in the pair
        report.times.push_back((k + 1) * grid.dt);
        ++collecting;
        ++next_output;
      }
      const long done = k + (pair ? 2 : 1);
      const bool output = ends_at_output(done);
      if (pair)
        bank.step_pair(k, grid.dt, output, first_output ? &report.filters : nullptr);
      else
        bank.step(k, grid.dt, output);
      collect_oldest(queued_before);  // not the pair's own: the host would wait for the device
      k = done;
      if (output) {
        record(k * grid.dt);
        ++next_output;
      }
    }
    if (progress) progress(progress_base + k);
    if (!checkpointing.saves()) continue;
    const int signal = stop_signal();
    if (signal != 0 || (k < grid.steps && clock.due())) save(k);
    if (signal != 0)
      throw RunInterrupted("stopped by " + signal_name(signal) + " after step " + std::to_string(k) + " of " +
                               std::to_string(grid.steps) + "; checkpoint written" + checkpointing.resume_hint,
                           signal);
  }
  collect();
  space.fence();
  report.step_loop_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - loop_start).count();
  report.steps_run = grid.steps - first_step;
  for (const auto& name : report.filters) report.scores.push_back(bank.scores(name, grid.steps + 1));
  for (const auto& name : bank_filters) report.filter_fields[name] = bank.summary_fields(name);
  for (const auto& e : outside) report.estimators[e->name()] = e->describe();
  report.truths_escaped = bank.truths_escaped();
  return report;
}

}  // namespace kushner
