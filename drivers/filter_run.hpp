#pragma once
// A whole filter run over a time grid: the bank of truths and filters stepped from 0 to T, metrics collected
// at the grid's output times and over the run. ASRE iterates over the whole horizon, so when it is selected
// a first pass runs the truths with ASRE alone to find, per member, the first iterate whose estimate
// trajectory changed less than the tolerance; the main pass then reports that iterate. The particle filter
// ("PF") and the exact or grid filter ("EXACT") run beside the bank when named among the filters; the
// particle filter (else the exact filter) is then the reference of rmse_ref. Shared by `kushner filter`,
// `kushner compare`, the tests and the benchmarks.
#include "drivers/exact_reference_estimator.hpp"
#include "drivers/filter_bank.hpp"
#include "drivers/particle_reference.hpp"
#include "drivers/progress.hpp"
#include "drivers/run_options.hpp"

#include <nlohmann/json.hpp>

#include <Kokkos_Core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace kushner {

/// ASRE iterations used, over the members (seed 001 Theorem 2 with a tolerance-based stop).
struct AsreIterations {
  std::vector<int> per_member;  // the iterate reported (0 = the frozen-coefficient Kalman-Bucy run)
  double mean = 0.0;
  int min = 0, max = 0;
  long not_converged = 0;  // members that reached max_iterations without meeting the tolerance
  long diverged = 0;       // members whose ASRE iterates diverged (or whose truth escaped): left out above
};

struct FilterReport {
  std::vector<std::string> filters;                 // report order
  std::vector<double> times;                        // output times
  std::vector<std::vector<FilterSnapshot>> series;  // [time][filter]
  std::vector<FilterScores> scores;                 // [filter], over the whole run
  long truths_escaped = 0;                          // members left out of every metric
  bool has_reference = false;
  std::string reference;                // the reference's name ("PF", "EXACT") when has_reference
  nlohmann::json estimators = nlohmann::json::object();  // name -> describe() of PF / EXACT
  AsreIterations asre;  // when ASRE is among the filters
};

/// Names of the estimators that run beside the bank rather than in it.
inline bool is_outside_estimator(const std::string& name) { return name == "PF" || name == "EXACT"; }

/// Called at t = 0 and at every output time with the bank and the outside estimators (PF, EXACT), e.g. to
/// record chosen members' trajectories.
template <class ExecSpace, class Model, class TruthModel = Model>
using OutputObserver =
    std::function<void(double t, const FilterBank<ExecSpace, Model, TruthModel>&,
                       const std::vector<const ReferenceEstimator<typename ExecSpace::memory_space>*>&)>;

/// Estimators a caller adds beside the bank (e.g. `kushner reproduce`'s exact quadrature for a deterministic
/// model, or a paper's printed variant of a filter); run_filters owns them from then on.
template <class ExecSpace>
using ExtraEstimators = std::vector<std::unique_ptr<ReferenceEstimator<typename ExecSpace::memory_space>>>;

namespace detail {

/// One pass of the truths with ASRE alone, member `i` iterated iterations[i] times; marks in `first` each
/// member's first iterate j >= 1 (among those run) with max_t |m^[j] - m^[j-1]| < tolerance, and in
/// `diverged` the members whose iterates (or truth) did not stay finite.
template <class ExecSpace, class Model, class TruthModel>
void asre_pass(const ExecSpace& space, const TruthModel& truth_model, const Model& filter_model, long members,
               std::uint32_t seed, const TimeGrid& grid, FilterConfig config, const std::vector<int>& iterations,
               std::vector<int>& first, std::vector<char>& diverged, Progress* progress, long progress_base) {
  config.asre_iterations = iterations;
  FilterBank<ExecSpace, Model, TruthModel> bank(space, truth_model, filter_model, members, seed, {"ASRE"}, config);
  for (long k = 0; k < grid.steps; ++k) {
    bank.step(k, grid.dt, false);
    if (progress) progress->update(progress_base + k + 1);
  }
  space.fence();
  if constexpr (AsreFilter<Model, typename ExecSpace::memory_space>::unsupported == nullptr) {
    const auto& slot = bank.template slot<AsreFilter>();
    const auto change = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), slot.filter.change);
    const auto status = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), slot.status);
    const auto truth_status = Kokkos::create_mirror_view_and_copy(Kokkos::HostSpace(), bank.truth_status());
    for (long member = 0; member < members; ++member) {
      if (status(member) != Status::ok || truth_status(member) != Status::ok) diverged[member] = 1;
      for (int i = 1; i <= iterations[member] && !diverged[member]; ++i)
        if (change(member, i) < config.asre_tolerance) {
          first[member] = i;
          break;
        }
    }
  }
}

}  // namespace detail

/// Per member, the first ASRE iterate i >= 1 with max_t |m^[i] - m^[i-1]| < tolerance (else max_iterations).
/// Iterates do not depend on how many follow them, so this runs the truths with ASRE alone twice: every
/// member iterated `asre_first_round` times, then only the members still unconverged up to max_iterations
/// (the others iterate 0 times there). `progress` advances by 2 grid.steps.
template <class ExecSpace, class Model, class TruthModel>
AsreIterations asre_iterations(const ExecSpace& space, const TruthModel& truth_model, const Model& filter_model,
                               long members, std::uint32_t seed, const TimeGrid& grid, const FilterConfig& config,
                               Progress* progress) {
  constexpr int asre_first_round = 10;  // most members of the seed models converge within it at tolerance 1e-6
  const int max_iterations = config.asre_max_iterations;
  std::vector<int> first(members, 0);
  std::vector<char> diverged(members, 0);
  detail::asre_pass(space, truth_model, filter_model, members, seed, grid, config,
                    std::vector<int>(members, std::min(asre_first_round, max_iterations)), first, diverged, progress,
                    0);
  std::vector<int> rest(members, 0);
  bool any = false;
  for (long member = 0; member < members; ++member)
    if (first[member] == 0 && !diverged[member] && max_iterations > asre_first_round)
      rest[member] = max_iterations, any = true;
  if (any)
    detail::asre_pass(space, truth_model, filter_model, members, seed, grid, config, rest, first, diverged, progress,
                      grid.steps);
  AsreIterations result;
  result.per_member.resize(members);
  result.min = max_iterations;
  double sum = 0.0;
  for (long member = 0; member < members; ++member) {
    result.per_member[member] = first[member] > 0 ? first[member] : max_iterations;
    if (diverged[member]) {
      ++result.diverged;
      continue;
    }
    if (first[member] == 0) ++result.not_converged;
    result.min = std::min(result.min, result.per_member[member]);
    result.max = std::max(result.max, result.per_member[member]);
    sum += result.per_member[member];
  }
  result.mean = members > result.diverged ? sum / (members - result.diverged) : std::nan("");
  return result;
}

/// Runs the filters `filters` (from select_estimators<Model>: bank filters, then "PF" and/or "EXACT") over
/// `grid`, and the `extra` estimators after them (reported after them, in their order). The truths follow
/// truth_model, the filters filter_model. With PF, EXACT or an extra estimator, every other estimate is also
/// scored against the reference's mean (rmse_ref): the first of PF, EXACT, extra[0], ... `progress` counts
/// steps of all passes: 3 grid.steps when ASRE is selected, else grid.steps.
template <class ExecSpace, class Model, class TruthModel>
FilterReport run_filters(const ExecSpace& space, const TruthModel& truth_model, const Model& filter_model, long members,
                         std::uint32_t seed, const TimeGrid& grid, const std::vector<std::string>& filters,
                         FilterConfig config, const ParticleSettings& particle = {}, Progress* progress = nullptr,
                         const OutputObserver<ExecSpace, Model, TruthModel>& observer = {},
                         ExtraEstimators<ExecSpace> extra = {}) {
  using MemSpace = typename ExecSpace::memory_space;
  FilterReport report;
  report.filters = filters;
  std::vector<std::string> bank_filters;
  std::vector<std::unique_ptr<ReferenceEstimator<MemSpace>>> outside;
  for (const auto& name : filters) {
    if (!is_outside_estimator(name)) {
      bank_filters.push_back(name);
    } else if (name == "PF") {
      if constexpr (particle_filter_unsupported<Model>() == nullptr)
        outside.push_back(std::make_unique<ParticleReference<ExecSpace, Model>>(space, filter_model, members, seed,
                                                                                particle));
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
  if (std::find(filters.begin(), filters.end(), "ASRE") != filters.end()) {
    report.asre = asre_iterations(space, truth_model, filter_model, members, seed, grid, config, progress);
    config.asre_iterations = report.asre.per_member;
  }
  FilterBank<ExecSpace, Model, TruthModel> bank(space, truth_model, filter_model, members, seed, bank_filters, config);
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
  auto record = [&](double t) {
    report.times.push_back(t);
    report.series.emplace_back();
    for (const auto& name : report.filters) report.series.back().push_back(bank.snapshot(name));
    if (observer) observer(t, bank, outside_view);
  };
  record(0.0);
  std::size_t next_output = 1;
  const long progress_base = report.asre.per_member.empty() ? 0 : 2 * grid.steps;  // after ASRE's passes
  for (long k = 0; k < grid.steps; ++k) {
    const bool output = next_output < grid.output_steps.size() && grid.output_steps[next_output] == k + 1;
    bank.step(k, grid.dt, output);
    if (output) {
      record((k + 1) * grid.dt);
      ++next_output;
    }
    if (progress) progress->update(progress_base + k + 1);
  }
  space.fence();
  for (const auto& name : report.filters) report.scores.push_back(bank.scores(name, grid.steps + 1));
  for (const auto& e : outside) report.estimators[e->name()] = e->describe();
  report.truths_escaped = bank.truths_escaped();
  return report;
}

}  // namespace kushner
