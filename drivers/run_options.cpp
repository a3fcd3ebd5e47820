#include "drivers/run_options.hpp"

#include "core/errors.hpp"
#include "drivers/whole_number_notation.hpp"

#include <CLI/CLI.hpp>

#include <cmath>
#include <limits>

namespace kushner {

void add_run_options(CLI::App& app, RunOptions& o) {
  // A value given twice (config file, then command line) takes the last one.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--model", o.model, "model name (see `kushner models`)")
      ->capture_default_str()
      ->each([&o](const std::string&) { o.model_given = true; });
  app.add_option("--model-file", o.model_file,
                 "a polynomial model from a TOML file instead of --model (README, \"Models\")");
  app.add_option("--set", o.sets, "model parameter, key=value (repeatable; matrices as 1,0;0,1)")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app.add_option("--members", o.members, "ensemble members M")
      ->capture_default_str()
      ->transform(whole_number_notation());
  app.add_option("--T", o.T, "time horizon (discrete-time models: the number of steps)")->capture_default_str();
  app.add_option("--dt", o.dt, "time step (discrete-time models: 1, the default for them)")
      ->capture_default_str()
      ->each([&o](const std::string&) { o.dt_given = true; });
  app.add_option("--seed", o.seed, "random seed, 0 .. 4294967295")
      ->capture_default_str()
      ->transform(whole_number_notation());
  app.add_option("--out", o.out, "output directory (created if missing)")->capture_default_str();
  app.add_option("--output-points", o.output_points,
                 "N, for the time points of timeseries.csv: 0, every (T/dt / N)-th step (rounded down) and T, "
                 "so N + 1 where N divides T/dt (at most T/dt + 1; the default is capped there)")
      ->capture_default_str()
      ->transform(whole_number_notation())
      ->each([&o](const std::string&) { o.output_points_given = true; });
  app.add_flag("--quiet", o.quiet, "no progress bar");
  app.add_option("--config", o.config, "read options from a TOML/INI file (keys: the long option names)");
}

void validate_run_options(const RunOptions& o) {
  KUSHNER_INPUT_REQUIRE(!(o.model_given && !o.model_file.empty()),
                        "--model-file: give either --model or --model-file, not both (the file defines the model)");
  KUSHNER_INPUT_REQUIRE(o.members > 0, "--members: must be positive (got " << o.members << ")");
  KUSHNER_INPUT_REQUIRE(
      o.members <= std::numeric_limits<std::int32_t>::max(),
      "--members: at most " << std::numeric_limits<std::int32_t>::max() << " (got " << o.members << ")");
  KUSHNER_INPUT_REQUIRE(std::isfinite(o.dt) && o.dt > 0.0, "--dt: must be positive (got " << o.dt << ")");
  KUSHNER_INPUT_REQUIRE(std::isfinite(o.T) && o.T > 0.0, "--T: must be positive (got " << o.T << ")");
  KUSHNER_INPUT_REQUIRE(o.seed >= 0 && o.seed <= 0xffffffffLL,
                        "--seed: must be in 0 .. 4294967295 (got " << o.seed << ")");
  KUSHNER_INPUT_REQUIRE(o.output_points > 0, "--output-points: must be positive (got " << o.output_points << ")");
  const double ratio = o.T / o.dt;
  const TimeGridProblem problem = time_grid_problem(o.T, o.dt);
  KUSHNER_INPUT_REQUIRE(problem != TimeGridProblem::dt_above_T,
                        "--dt: larger than --T (" << o.dt << " > " << o.T << ")");
  KUSHNER_INPUT_REQUIRE(problem != TimeGridProblem::too_many_steps,
                        "--dt: too small for --T (" << ratio << " steps; at most 4e9)");
  KUSHNER_INPUT_REQUIRE(problem != TimeGridProblem::not_whole_steps,
                        "--T: must be a whole number of --dt steps (T/dt = " << ratio << ")");
  const long time_points = std::lround(ratio) + 1;  // 0, dt, ..., T
  KUSHNER_INPUT_REQUIRE(!o.output_points_given || o.output_points <= time_points,
                        "--output-points: must be at most T/dt + 1 = "
                            << time_points << ", the time points 0, dt, ..., T (got " << o.output_points << ")");
}

RunOptions options_for_model_time(RunOptions o, bool discrete_time) {
  if (!discrete_time) return o;
  KUSHNER_INPUT_REQUIRE(!o.dt_given || o.dt == 1.0,
                        "--dt: a discrete-time model steps k = 0, 1, ..., T; --dt must be 1 (got " << o.dt << ")");
  o.dt = 1.0;
  validate_run_options(o);
  return o;
}

}  // namespace kushner
