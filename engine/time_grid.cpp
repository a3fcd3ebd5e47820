#include "engine/time_grid.hpp"

#include "core/errors.hpp"

#include <algorithm>
#include <cmath>

namespace kushner {

TimeGridProblem time_grid_problem(double T, double dt) {
  const double ratio = T / dt;
  if (ratio < 0.5) return TimeGridProblem::dt_above_T;
  if (ratio >= 4.0e9) return TimeGridProblem::too_many_steps;
  if (std::fabs(ratio - std::lround(ratio)) > 1e-9 * ratio) return TimeGridProblem::not_whole_steps;
  return TimeGridProblem::none;
}

TimeGrid make_time_grid(double T, double dt, int output_points) {
  KUSHNER_REQUIRE(time_grid_problem(T, dt) == TimeGridProblem::none, "T = " << T << ", dt = " << dt);
  KUSHNER_REQUIRE(output_points > 0, "output_points = " << output_points);
  TimeGrid grid;
  grid.steps = std::lround(T / dt);
  grid.dt = dt;
  const long stride = std::max(1L, grid.steps / output_points);
  for (long k = 0; k < grid.steps; k += stride) grid.output_steps.push_back(k);
  grid.output_steps.push_back(grid.steps);
  return grid;
}

}  // namespace kushner
