// Truth simulation step (Euler-Maruyama, all members in one kernel): member-steps per second, alone and with an output
// step's moments after it, next to a deep_copy of the same bytes (the memory floor) in the same binary; and the host's
// segments of steps, as `kushner simulate` takes them.
#include "engine/truth_bank.hpp"
#include "models/cubic_oscillator_model.hpp"
#include "models/sine_model.hpp"
#include "perf/bench_timing.hpp"

#include <benchmark/benchmark.h>

#include <vector>

namespace kushner {
namespace {

/// Bytes a step must move per member: read and write x, write the observation increment.
template <class Model>
constexpr double bytes_per_member_step() {
  return 8.0 * (2 * Model::state_dim + Model::obs_dim);
}

template <class Model>
void BM_TruthStep(benchmark::State& state) {
  using Space = Kokkos::DefaultExecutionSpace;
  const long members = state.range(0);
  TruthBank<Space, Model> bank(Space(), Model{}, members, 42);
  time_truth_steps(state, bank);
  using C = benchmark::Counter;
  state.counters["GB_per_s"] = C(1e-9 * bytes_per_member_step<Model>() * members, C::kIsIterationInvariantRate);
  const auto moments = ensemble_moments(Space(), bank.state());
  for (double v : moments.mean)
    if (!std::isfinite(v)) state.SkipWithError("non-finite state");
}

/// A step and the ensemble moments of the state it leaves: `kushner simulate`'s output step (every step by default).
template <class Model>
void BM_OutputStep(benchmark::State& state) {
  using Space = Kokkos::DefaultExecutionSpace;
  TruthBank<Space, Model> bank(Space(), Model{}, state.range(0), 42);
  time_truth_steps(state, bank, /*moments=*/true);
}

/// `kushner simulate`'s host loop: segments of truth_segment_steps steps, each block of members through all of them in
/// its core's cache (TruthBank::step_segment), the moments at every step (`output` 1, simulate's default where the
/// output points are as many as the steps) or at none (0). Skipped where the bank steps one step at a time (a GPU).
template <class Model>
void BM_TruthSegment(benchmark::State& state) {
  using Space = Kokkos::DefaultExecutionSpace;
  const long members = state.range(0);
  TruthBank<Space, Model> bank(Space(), Model{}, members, 42);
  if (!bank.steps_in_segments()) {
    state.SkipWithError("this backend steps one step at a time");
    return;
  }
  const std::vector<char> outputs(truth_segment_steps, static_cast<char>(state.range(1)));
  long k = 0;
  for (auto _ : state) {
    Kokkos::Timer timer;
    benchmark::DoNotOptimize(bank.step_segment(k, 1e-3, outputs).size());
    k += truth_segment_steps;
    state.SetIterationTime(timer.seconds());
  }
  using C = benchmark::Counter;
  state.counters["member_steps_per_s"] =
      C(static_cast<double>(members) * truth_segment_steps, C::kIsIterationInvariantRate);
}

/// ensemble_moments of a bank's state alone (no step): `kept` 1 with block rows and a (page-locked on a GPU) host copy
/// kept from call to call, as an output step after another takes them; 0 with rows of its own each time, as a single
/// reduction (simulate's first output, a filter's end-of-run score) takes them.
template <class Model>
void BM_Moments(benchmark::State& state) {
  using Space = Kokkos::DefaultExecutionSpace;
  TruthBank<Space, Model> bank(Space(), Model{}, state.range(0), 42);
  MomentRows<Space::memory_space> rows;
  const Space space;
  for (auto _ : state) {
    space.fence();
    Kokkos::Timer timer;
    if (state.range(1) != 0)
      benchmark::DoNotOptimize(ensemble_moments(space, bank.state(), rows).mean);
    else
      benchmark::DoNotOptimize(ensemble_moments(space, bank.state()).mean);
    state.SetIterationTime(timer.seconds());
  }
}

/// The physical floor: copying the bytes one step moves.
template <class Model>
void BM_StreamCopy(benchmark::State& state) {
  time_stream_copy(state, state.range(0) * static_cast<long>(bytes_per_member_step<Model>() / 16.0));
}

BENCHMARK_TEMPLATE(BM_TruthStep, SineModel)->ArgName("members")->Arg(1 << 20)->Arg(1000000)->UseManualTime();
BENCHMARK_TEMPLATE(BM_StreamCopy, SineModel)->ArgName("members")->Arg(1000000)->UseManualTime();
BENCHMARK_TEMPLATE(BM_TruthStep, CubicOscillatorModel)->ArgName("members")->Arg(1000000)->UseManualTime();
BENCHMARK_TEMPLATE(BM_StreamCopy, CubicOscillatorModel)->ArgName("members")->Arg(1000000)->UseManualTime();
BENCHMARK_TEMPLATE(BM_TruthSegment, SineModel)->ArgNames({"members", "output"})->Args({1000000, 1})->UseManualTime();
BENCHMARK_TEMPLATE(BM_TruthSegment, CubicOscillatorModel)
    ->ArgNames({"members", "output"})
    ->Args({1000000, 1})
    ->Args({1000000, 0})
    ->UseManualTime();
BENCHMARK_TEMPLATE(BM_OutputStep, SineModel)->ArgName("members")->Arg(1000000)->UseManualTime();
BENCHMARK_TEMPLATE(BM_OutputStep, CubicOscillatorModel)->ArgName("members")->Arg(1000000)->UseManualTime();
BENCHMARK_TEMPLATE(BM_Moments, SineModel)
    ->ArgNames({"members", "kept"})
    ->Args({1000000, 1})
    ->Args({1000000, 0})
    ->UseManualTime();

}  // namespace
}  // namespace kushner
