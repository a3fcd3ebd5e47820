#pragma once
// The time grid of a run: steps of dt from 0 to T, and the steps at which statistics are recorded.
#include <vector>

namespace kushner {

struct TimeGrid {
  long steps = 0;  // T / dt
  double dt = 0.0;
  std::vector<long> output_steps;  // steps at which ensemble statistics are recorded: 0, stride, ..., steps
};

/// What is wrong with T and dt as a grid (both positive and finite), if anything.
enum class TimeGridProblem {
  none,
  dt_above_T,       // fewer than half a step
  too_many_steps,   // 4e9 steps or more (step counters are 32-bit)
  not_whole_steps,  // T / dt is not a whole number (to 1e-9 relative)
};
TimeGridProblem time_grid_problem(double T, double dt);

/// The grid of T / dt steps with about `output_points` output steps (at least every step). Requires
/// time_grid_problem(T, dt) == none: callers check user input first (drivers/run_options.cpp).
TimeGrid make_time_grid(double T, double dt, int output_points);

}  // namespace kushner
