// The whole filter bank's step (truths + every filter the model supports, one fused kernel): member-steps per
// second, next to the truth step alone in the same binary. ASRE runs a fixed 8 iterates per member (its
// convergence passes are not part of a step; the seed models need 5-8 on average at tolerance 1e-6).
#include "engine/filter_bank.hpp"
#include "kernels/filters/filter_list.hpp"
#include "models/cubic_oscillator_model.hpp"
#include "models/sine_model.hpp"
#include "perf/bench_timing.hpp"

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

namespace kushner {
namespace {

using Space = Kokkos::DefaultExecutionSpace;
constexpr int asre_iterates = 8;

template <class Model>
void BM_FilterBankStep(benchmark::State& state) {
  const long members = state.range(0);
  const Space space;
  const std::vector<std::string> filters = supported_filters(Model{});
  OptionValues settings;
  settings.set("asre_max_iterations", static_cast<long>(asre_iterates));
  FilterBank<Space, Model> bank(space, Model{}, Model{}, members, 42, filters, settings);
  long k = 0;
  for (auto _ : state) {
    space.fence();
    Kokkos::Timer timer;
    bank.step(k++, 1e-3, false);
    space.fence();
    state.SetIterationTime(timer.seconds());
  }
  using C = benchmark::Counter;
  state.counters["member_steps_per_s"] = C(static_cast<double>(members), C::kIsIterationInvariantRate);
  state.counters["filters"] = static_cast<double>(filters.size());
  std::string label;
  for (const auto& name : filters) {
    label += (label.empty() ? "" : ",") + name;
    if (bank.scores(name, k + 1).diverged > 0) state.SkipWithError(("diverged members in " + name).c_str());
  }
  state.SetLabel(label);
}

/// The command line's bank (`kushner filter --filters EKF,SOF,QLF,KBL`) with every step an output step, as
/// engine/filter_run.hpp runs it: the step, then its reductions queued (start_snapshots) and collected once the next
/// step is queued (finish_snapshots). Arg 1 = 0: the same steps with no output (what an output step adds is the
/// difference of the two).
template <class Model>
void BM_FilterBankOutputSteps(benchmark::State& state) {
  const long members = state.range(0);
  const bool output = state.range(1) != 0;
  const Space space;
  const std::vector<std::string> filters{"EKF", "SOF", "QLF", "KBL"};
  FilterBank<Space, Model> bank(space, Model{}, Model{}, members, 42, filters);
  long k = 0;
  bool pending = false;
  for (auto _ : state) {
    space.fence();
    Kokkos::Timer timer;
    bank.step(k++, 1e-3, output);
    if (pending) bank.finish_snapshots();
    if (output) bank.start_snapshots(filters);
    pending = output;
    space.fence();
    state.SetIterationTime(timer.seconds());
  }
  if (pending) bank.finish_snapshots();
  using C = benchmark::Counter;
  state.counters["member_steps_per_s"] = C(static_cast<double>(members), C::kIsIterationInvariantRate);
  for (const auto& name : filters)
    if (bank.scores(name, k + 1).diverged > 0) state.SkipWithError(("diverged members in " + name).c_str());
}

/// BM_FilterBankOutputSteps' steps taken FilterBank::segment_steps at a time (FilterBank::start_segment: on the host in
/// chunks, as engine/filter_run.hpp takes them; on a GPU in teams). Arg 2 = 1: members 0 .. 2 watched (`compare`'s
/// traced members: their truths and each filter's m and P copied at every output step); 0: none (`kushner filter`).
template <class Model>
void BM_FilterBankSegments(benchmark::State& state) {
  const long members = state.range(0);
  const bool output = state.range(1) != 0;
  const Space space;
  const std::vector<std::string> filters{"EKF", "SOF", "QLF", "KBL"};
  using Bank = FilterBank<Space, Model>;
  Bank bank(space, Model{}, Model{}, members, 42, filters);
  const std::vector<WatchedElement> watched =
      bank.member_elements(state.range(2) != 0 ? std::vector<long>{0, 1, 2} : std::vector<long>{}, filters);
  const std::vector<char> outputs(Bank::segment_steps, output ? 1 : 0);
  long k = 0;
  for (auto _ : state) {
    Kokkos::Timer timer;
    bank.start_segment(k, 1e-3, outputs, filters, watched);
    if (k > 0) bank.finish_segment();  // the segment before, as run_filters finishes it: while this one runs
    k += Bank::segment_steps;
    state.SetIterationTime(timer.seconds());
  }
  if (k > 0) bank.finish_segment();
  using C = benchmark::Counter;
  state.counters["member_steps_per_s"] =
      C(static_cast<double>(members) * Bank::segment_steps, C::kIsIterationInvariantRate);
  for (const auto& name : filters)
    if (bank.scores(name, k + 1).diverged > 0) state.SkipWithError(("diverged members in " + name).c_str());
}

/// The baseline: the same truths stepped alone (what `kushner simulate` does per step).
template <class Model>
void BM_TruthStepAlone(benchmark::State& state) {
  const long members = state.range(0);
  TruthBank<Space, Model> bank(Space(), Model{}, members, 42);
  time_truth_steps(state, bank);
}

BENCHMARK_TEMPLATE(BM_FilterBankStep, SineModel)
    ->ArgName("members")
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->UseManualTime();
BENCHMARK_TEMPLATE(BM_FilterBankOutputSteps, SineModel)
    ->ArgNames({"members", "output"})
    ->Args({8192, 1})
    ->Args({8192, 0})
    ->Args({1000000, 1})
    ->Args({1000000, 0})
    ->UseManualTime();
BENCHMARK_TEMPLATE(BM_FilterBankSegments, SineModel)
    ->ArgNames({"members", "output", "watched"})
    ->Args({8192, 1, 1})
    ->Args({1000000, 1, 1})
    ->Args({1000000, 0, 1})
    ->Args({1000000, 1, 0})
    ->Args({1000000, 0, 0})
    ->UseManualTime();
BENCHMARK_TEMPLATE(BM_TruthStepAlone, SineModel)
    ->ArgName("members")
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->UseManualTime();
BENCHMARK_TEMPLATE(BM_FilterBankStep, CubicOscillatorModel)
    ->ArgName("members")
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->UseManualTime();
BENCHMARK_TEMPLATE(BM_TruthStepAlone, CubicOscillatorModel)
    ->ArgName("members")
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->UseManualTime();

}  // namespace
}  // namespace kushner
