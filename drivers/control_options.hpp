#pragma once
// Options of `kushner control`: the run options, the controllers LAW@ESTIMATOR (and the seeds' aliases), the cost
// weights, and the estimators' settings (the filters' options and the particle filter's, as for `compare`).
#include "drivers/cli_app.hpp"
#include "drivers/filter_options.hpp"

#include <string>
#include <utility>
#include <vector>

namespace kushner {

struct ControlOptions : FilterOptions {
  std::string controllers = "NONE@state,LQR@state,LQR@EKF,LQR@PF";
  std::vector<std::string> cost;  // "key=value": F, Q, R, target
  std::string reference =
      "auto";             // the optimal-cost reference: auto, hjb, direct, none (engine/control/cost_reference.hpp)
  long trace_member = 0;  // the member whose paths go to timeseries.csv and the plots
  bool plots = true;
};

/// --controllers, --cost, --trace-member, --no-plots, and the run, filter and particle options.
void add_control_options(CLI::App& app, ControlOptions& options);

/// The seeds' names for controllers and what they stand for: LQG = LQR@KB, ASRE-C = ASRE@ASRE, ...
const std::vector<std::pair<std::string, std::string>>& controller_aliases();

}  // namespace kushner
