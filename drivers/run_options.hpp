#pragma once
// Options shared by the commands that run a bank (simulate, filter, compare), checked once here.
#include "drivers/cli_app.hpp"
#include "engine/time_grid.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace kushner {

struct RunOptions {
  std::string model = "sine";
  bool model_given = false;       // --model was on the command line (or in --config)
  std::string model_file;         // --model-file FILE: a polynomial model (drivers/model_file.hpp)
  std::vector<std::string> sets;  // "key=value"
  long members = 1000;
  double T = 10.0;
  double dt = 1e-3;
  bool dt_given = false;  // --dt was given (a discrete-time model's step is 1)
  long long seed = 1;
  std::string out = "kushner-out";
  int output_points = 200;
  bool output_points_given = false;  // --output-points was given (the default is capped at the steps quietly)
  bool quiet = false;
  std::string config;  // --config FILE, already expanded into the fields above by the command line (command_line.cpp)
};

/// --model, --model-file, --set, --members, --T, --dt, --seed, --out, --output-points, --quiet, --config.
void add_run_options(CLI::App& app, RunOptions& options);

/// InputError (one line naming the option) for any value a run cannot use.
void validate_run_options(const RunOptions& options);

/// The options as a model of this time reads them: a discrete-time model steps k = 0, 1, ..., T, so dt is 1 (and
/// --dt, if given, must say so); validated again. Continuous time: unchanged.
RunOptions options_for_model_time(RunOptions options, bool discrete_time);

}  // namespace kushner
