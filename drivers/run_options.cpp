#include "drivers/run_options.hpp"

#include "kernels/errors.hpp"

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
  app.add_option("--members", o.members, "ensemble members M")->capture_default_str();
  app.add_option("--T", o.T, "time horizon")->capture_default_str();
  app.add_option("--dt", o.dt, "time step")->capture_default_str();
  app.add_option("--seed", o.seed, "random seed, 0 .. 4294967295")->capture_default_str();
  app.add_option("--out", o.out, "output directory (created if missing)")->capture_default_str();
  app.add_option("--output-points", o.output_points, "number of time points in timeseries.csv")->capture_default_str();
  app.add_flag("--quiet", o.quiet, "no progress bar");
  app.add_option("--config", o.config, "read options from a TOML/INI file (keys: the long option names)");
}

void validate_run_options(const RunOptions& o) {
  KUSHNER_INPUT_REQUIRE(!(o.model_given && !o.model_file.empty()),
                        "--model-file: give either --model or --model-file, not both (the file defines the model)");
  KUSHNER_INPUT_REQUIRE(o.members > 0, "--members: must be positive (got " << o.members << ")");
  KUSHNER_INPUT_REQUIRE(o.members <= std::numeric_limits<std::int32_t>::max(),
                        "--members: at most " << std::numeric_limits<std::int32_t>::max() << " (got " << o.members << ")");
  KUSHNER_INPUT_REQUIRE(std::isfinite(o.dt) && o.dt > 0.0, "--dt: must be positive (got " << o.dt << ")");
  KUSHNER_INPUT_REQUIRE(std::isfinite(o.T) && o.T > 0.0, "--T: must be positive (got " << o.T << ")");
  KUSHNER_INPUT_REQUIRE(o.seed >= 0 && o.seed <= 0xffffffffLL, "--seed: must be in 0 .. 4294967295 (got " << o.seed << ")");
  KUSHNER_INPUT_REQUIRE(o.output_points > 0, "--output-points: must be positive (got " << o.output_points << ")");
  make_time_grid(o.T, o.dt, o.output_points);
}

TimeGrid make_time_grid(double T, double dt, int output_points) {
  const double ratio = T / dt;
  KUSHNER_INPUT_REQUIRE(ratio >= 0.5, "--dt: larger than --T (" << dt << " > " << T << ")");
  KUSHNER_INPUT_REQUIRE(ratio < 4.0e9, "--dt: too small for --T (" << ratio << " steps; at most 4e9)");
  TimeGrid grid;
  grid.steps = std::lround(ratio);
  KUSHNER_INPUT_REQUIRE(std::fabs(ratio - grid.steps) <= 1e-9 * ratio,
                        "--T: must be a whole number of --dt steps (T/dt = " << ratio << ")");
  grid.dt = dt;
  const long stride = std::max(1L, grid.steps / output_points);
  for (long k = 0; k < grid.steps; k += stride) grid.output_steps.push_back(k);
  grid.output_steps.push_back(grid.steps);
  return grid;
}

}  // namespace kushner
