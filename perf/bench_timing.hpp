#pragma once
// What several benchmarks time the same way: a bank of truths stepped one step at a time, and the copy of a number of
// bytes that is a kernel's memory floor. Each iteration is timed between fences (UseManualTime), so a GPU's
// asynchronous launch is counted to its end.
#include "engine/truth_bank.hpp"

#include <benchmark/benchmark.h>
#include <Kokkos_Core.hpp>

namespace kushner {

/// Steps `bank` once per iteration (what `kushner simulate` does per step; with `moments`, what it does per output
/// step: TruthBank::step_and_moments): member_steps_per_s.
template <class Space, class Model>
void time_truth_steps(benchmark::State& state, TruthBank<Space, Model>& bank, const bool moments = false) {
  const auto members = static_cast<double>(bank.state().extent(0));
  const Space space;
  long k = 0;
  for (auto _ : state) {
    space.fence();
    Kokkos::Timer timer;
    if (moments)
      benchmark::DoNotOptimize(bank.step_and_moments(k++, 1e-3).mean);
    else
      bank.step(k++, 1e-3);
    space.fence();
    state.SetIterationTime(timer.seconds());
  }
  using C = benchmark::Counter;
  state.counters["member_steps_per_s"] = C(members, C::kIsIterationInvariantRate);
}

/// The physical floor: a deep_copy of `doubles` doubles (half the bytes read, half written) on the default space:
/// GB_per_s of the bytes moved.
inline void time_stream_copy(benchmark::State& state, const long doubles) {
  using Space = Kokkos::DefaultExecutionSpace;
  Kokkos::View<double*, Space::memory_space> a("a", doubles), b("b", doubles);
  Kokkos::deep_copy(a, 1.0);
  const Space space;
  for (auto _ : state) {
    space.fence();
    Kokkos::Timer timer;
    Kokkos::deep_copy(space, b, a);
    space.fence();
    state.SetIterationTime(timer.seconds());
  }
  using C = benchmark::Counter;
  state.counters["GB_per_s"] = C(1e-9 * 16.0 * doubles, C::kIsIterationInvariantRate);
}

}  // namespace kushner
