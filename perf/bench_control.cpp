// The closed loop's step (engine/control/closed_loop.hpp): member-steps per second of the car model under four
// controllers (LQR@state, ASRE@state, LQR@EKF, POLY3@EKF: one kernel launch each per step), next to the truth step
// alone in the same binary. Bytes moved per member-step, the floor's numerator: the state estimator reads and
// writes x (2 + 2 doubles), writes dy (2) and u (1), reads and writes the cost totals (2 + 2): 88 B; a bank filter
// adds its m (2 + 2) and packed P (3 + 3): 168 B; the gains (7 doubles a step) are shared by all members.
#include "engine/control/closed_loop.hpp"
#include "engine/control/control_laws.hpp"
#include "models/car_model.hpp"

#include <benchmark/benchmark.h>

#include <string>
#include <vector>

namespace kushner {
namespace {

constexpr long horizon_steps = 300;  // T = 0.3, as in Basin's car examples
constexpr double dt = 1e-3;

CarModel bench_car() {
  CarModel car;
  car.v = 17.0;
  car.l = 2.0;
  car.u = 0.0;
  car.q = 0.1;  // some process noise, so that every member differs
  car.x0_mean = Vec<2>{{0.1, 0.1}};
  car.x0_cov = Mat<2, 2>::diagonal(1e-4);
  car.prior_mean = car.x0_mean;
  car.prior_cov = Mat<2, 2>::diagonal(1e-2);
  return car;
}

QuadraticCost<2, 1> bench_cost() {
  QuadraticCost<2, 1> cost;
  cost.F(0, 0) = 1.0;
  cost.target[0] = 1.0;
  return cost;
}

template <class Space>
void BM_ClosedLoopCar4(benchmark::State& state) {
  using MemSpace = typename Space::memory_space;
  const long members = state.range(0);
  const Space space;
  const CarModel car = bench_car();
  const QuadraticCost<2, 1> cost = bench_cost();
  TimeGrid grid;
  grid.steps = horizon_steps;
  grid.dt = dt;
  const std::vector<std::pair<std::string, std::string>> controllers = {
      {"LQR", "state"}, {"ASRE", "state"}, {"LQR", "EKF"}, {"POLY3", "EKF"}};
  std::vector<ControlLoop<Space, CarModel>> loops;
  loops.reserve(controllers.size());
  for (const auto& [law, estimator] : controllers)
    loops.emplace_back(space, car, members, 42, estimator, make_law<CarModel, MemSpace>(law, car, cost, grid).law,
                       cost);
  long k = 0;
  for (auto _ : state) {
    space.fence();
    Kokkos::Timer timer;
    for (auto& loop : loops) loop.step(k % horizon_steps, dt, false);
    space.fence();
    state.SetIterationTime(timer.seconds());
    ++k;
  }
  using C = benchmark::Counter;
  state.counters["controllers"] = static_cast<double>(controllers.size());
  state.counters["member_steps_per_s"] = C(static_cast<double>(members), C::kIsIterationInvariantRate);
  state.counters["controller_member_steps_per_s"] =
      C(static_cast<double>(members * controllers.size()), C::kIsIterationInvariantRate);
  state.counters["bytes_per_s"] =
      C(static_cast<double>(members) * (2 * 88 + 2 * 168), C::kIsIterationInvariantRate);  // the floor's traffic
  for (const auto& loop : loops)
    if (loop.truths_escaped() > 0) state.SkipWithError("a truth escaped");
}

template <class Space>
void BM_CarTruthStepAlone(benchmark::State& state) {
  const long members = state.range(0);
  const Space space;
  TruthBank<Space, CarModel> bank(space, bench_car(), members, 42);
  long k = 0;
  for (auto _ : state) {
    space.fence();
    Kokkos::Timer timer;
    bank.step(k++, dt);
    space.fence();
    state.SetIterationTime(timer.seconds());
  }
  using C = benchmark::Counter;
  state.counters["member_steps_per_s"] = C(static_cast<double>(members), C::kIsIterationInvariantRate);
}

// The default execution space (the GPU in a CUDA build) and, where it differs, the host's (OpenMP: set
// OMP_NUM_THREADS=2 for the two-thread figure).
using Device = Kokkos::DefaultExecutionSpace;
using Host = Kokkos::DefaultHostExecutionSpace;
BENCHMARK_TEMPLATE(BM_ClosedLoopCar4, Device)
    ->ArgName("members")
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->UseManualTime();
BENCHMARK_TEMPLATE(BM_CarTruthStepAlone, Device)
    ->ArgName("members")
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->UseManualTime();
#if defined(KOKKOS_ENABLE_CUDA)
BENCHMARK_TEMPLATE(BM_ClosedLoopCar4, Host)->ArgName("members")->Arg(10000)->Arg(100000)->Arg(1000000)->UseManualTime();
BENCHMARK_TEMPLATE(BM_CarTruthStepAlone, Host)
    ->ArgName("members")
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->UseManualTime();
#endif

}  // namespace
}  // namespace kushner
