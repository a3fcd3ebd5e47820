#pragma once
// What several benchmarks time the same way: a bank of truths stepped one step at a time, and the copy of a number of
// bytes that is a kernel's memory floor. Each iteration is timed between fences (UseManualTime), so a GPU's
// asynchronous launch is counted to its end.
#include "engine/truth_bank.hpp"

#include <benchmark/benchmark.h>
#include <Kokkos_Core.hpp>

namespace kushner {

/// What time_truth_steps does after each step by default: nothing.
struct NothingAfterStep {
  void operator()() const {}
};

/// Steps `bank` once per iteration (what `kushner simulate` does per step), then calls after_step() inside the timing
/// (an output step's moments): member_steps_per_s.
template <class Space, class Model, class AfterStep = NothingAfterStep>
void time_truth_steps(benchmark::State& state, TruthBank<Space, Model>& bank, const AfterStep& after_step = {}) {
  const auto members = static_cast<double>(bank.state().extent(0));
  const Space space;
  long k = 0;
  for (auto _ : state) {
    space.fence();
    Kokkos::Timer timer;
    bank.step(k++, 1e-3);
    after_step();
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
