// Truth simulation step (Euler-Maruyama, all members in one kernel): member-steps per second, next to a
// deep_copy of the same bytes (the memory floor) in the same binary.
#include "engine/truth_bank.hpp"
#include "models/cubic_oscillator_model.hpp"
#include "models/sine_model.hpp"

#include <benchmark/benchmark.h>

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
  const Space space;
  TruthBank<Space, Model> bank(space, Model{}, members, 42);
  long k = 0;
  for (auto _ : state) {
    space.fence();
    Kokkos::Timer timer;
    bank.step(k++, 1e-3);
    space.fence();
    state.SetIterationTime(timer.seconds());
  }
  using C = benchmark::Counter;
  state.counters["member_steps_per_s"] = C(static_cast<double>(members), C::kIsIterationInvariantRate);
  state.counters["GB_per_s"] = C(1e-9 * bytes_per_member_step<Model>() * members, C::kIsIterationInvariantRate);
  const auto moments = ensemble_moments(space, bank.state());
  for (double v : moments.mean)
    if (!std::isfinite(v)) state.SkipWithError("non-finite state");
}

/// The physical floor: copying the bytes one step moves.
template <class Model>
void BM_StreamCopy(benchmark::State& state) {
  using Space = Kokkos::DefaultExecutionSpace;
  const long members = state.range(0);
  const long doubles = members * static_cast<long>(bytes_per_member_step<Model>() / 16.0);  // half read, half written
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

BENCHMARK_TEMPLATE(BM_TruthStep, SineModel)->ArgName("members")->Arg(1 << 20)->Arg(1000000)->UseManualTime();
BENCHMARK_TEMPLATE(BM_StreamCopy, SineModel)->ArgName("members")->Arg(1000000)->UseManualTime();
BENCHMARK_TEMPLATE(BM_TruthStep, CubicOscillatorModel)->ArgName("members")->Arg(1000000)->UseManualTime();
BENCHMARK_TEMPLATE(BM_StreamCopy, CubicOscillatorModel)->ArgName("members")->Arg(1000000)->UseManualTime();

}  // namespace
}  // namespace kushner
