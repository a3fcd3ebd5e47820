#pragma once
// Options shared by the commands that run a bank (simulate, and later filter/compare), their validation,
// and the time grid they imply.
#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace kushner {

struct RunOptions {
  std::string model = "sine";
  bool model_given = false;       // --model was on the command line (or in --config)
  std::string model_file;         // --model-file FILE: a polynomial model (models/model_file.hpp)
  std::vector<std::string> sets;  // "key=value"
  long members = 1000;
  double T = 10.0;
  double dt = 1e-3;
  long long seed = 1;
  std::string out = "kushner-out";
  int output_points = 200;
  bool quiet = false;
  std::string config;  // --config FILE, already expanded into the fields above by main()
};

/// --model, --model-file, --set, --members, --T, --dt, --seed, --out, --output-points, --quiet, --config.
void add_run_options(CLI::App& app, RunOptions& options);

/// InputError (one line naming the option) for any value a run cannot use.
void validate_run_options(const RunOptions& options);

struct TimeGrid {
  long steps = 0;                 // T / dt
  double dt = 0.0;
  std::vector<long> output_steps; // steps at which ensemble statistics are recorded: 0, stride, ..., steps
};

/// InputError unless T is a whole number of steps dt (to 1e-9 relative).
TimeGrid make_time_grid(double T, double dt, int output_points);

}  // namespace kushner
