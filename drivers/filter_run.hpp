#pragma once
// A whole filter run over a time grid: the bank of truths and filters stepped from 0 to T, metrics collected
// at the grid's output times and over the run. ASRE iterates over the whole horizon, so when it is selected
// a first pass runs the truths with ASRE alone to find, per member, the first iterate whose estimate
// trajectory changed less than the tolerance; the main pass then reports that iterate. Shared by
// `kushner filter`, the tests and the benchmarks.
#include "drivers/filter_bank.hpp"
#include "drivers/progress.hpp"
#include "drivers/reference_mean.hpp"
#include "drivers/run_options.hpp"

#include <Kokkos_Core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
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
  AsreIterations asre;  // when ASRE is among the filters
};

namespace detail {

/// One pass of the truths with ASRE alone, member `i` iterated iterations[i] times; marks in `first` each
/// member's first iterate j >= 1 (among those run) with max_t |m^[j] - m^[j-1]| < tolerance, and in
/// `diverged` the members whose iterates (or truth) did not stay finite.
template <class ExecSpace, class Model>
void asre_pass(const ExecSpace& space, const Model& truth_model, const Model& filter_model, long members,
               std::uint32_t seed, const TimeGrid& grid, FilterConfig config, const std::vector<int>& iterations,
               std::vector<int>& first, std::vector<char>& diverged, Progress* progress, long progress_base) {
  config.asre_iterations = iterations;
  FilterBank<ExecSpace, Model> bank(space, truth_model, filter_model, members, seed, {"ASRE"}, config);
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
template <class ExecSpace, class Model>
AsreIterations asre_iterations(const ExecSpace& space, const Model& truth_model, const Model& filter_model,
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

/// Runs the filters `filters` (from select_filters<Model>) over `grid`. The truths follow truth_model, the
/// filters filter_model. With a `reference`, every filter is also scored against its mean (rmse_ref).
/// `progress` counts steps of all passes: 3 grid.steps when ASRE is selected, else grid.steps.
template <class ExecSpace, class Model>
FilterReport run_filters(const ExecSpace& space, const Model& truth_model, const Model& filter_model, long members,
                         std::uint32_t seed, const TimeGrid& grid, const std::vector<std::string>& filters,
                         FilterConfig config, ReferenceMean<typename ExecSpace::memory_space>* reference = nullptr,
                         Progress* progress = nullptr) {
  FilterReport report;
  report.filters = filters;
  report.has_reference = reference != nullptr;
  if (std::find(filters.begin(), filters.end(), "ASRE") != filters.end()) {
    report.asre = asre_iterations(space, truth_model, filter_model, members, seed, grid, config, progress);
    config.asre_iterations = report.asre.per_member;
  }
  FilterBank<ExecSpace, Model> bank(space, truth_model, filter_model, members, seed, filters, config);
  bank.set_reference(reference);
  auto record = [&](double t) {
    report.times.push_back(t);
    report.series.emplace_back();
    for (const auto& name : filters) report.series.back().push_back(bank.snapshot(name));
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
  for (const auto& name : filters) report.scores.push_back(bank.scores(name, grid.steps + 1));
  report.truths_escaped = bank.truths_escaped();
  return report;
}

}  // namespace kushner
