#include "drivers/control_options.hpp"

#include "drivers/whole_number_notation.hpp"

#include <CLI/CLI.hpp>

namespace kushner {

void add_control_options(CLI::App& app, ControlOptions& o) {
  add_filter_options(app, o);
  app.remove_option(app.get_option("--filters"));  // a controller names its own estimator
  app.add_option("--controllers", o.controllers, "comma-separated LAW@ESTIMATOR or aliases (see `kushner controllers`)")
      ->capture_default_str();
  app.add_option("--cost", o.cost,
                 "cost weight key=value: F (terminal), Q (running state), R (control), target (x*); "
                 "J = (x(T)-x*)'F(x(T)-x*) + int (x-x*)'Q(x-x*) + u'Ru dt; default F = Q = I, R = I, x* = 0")
      ->allow_extra_args(false);
  app.add_option("--reference", o.reference,
                 "optimal-cost reference J*: auto (direct for a deterministic problem, else hjb for dimension 1-2), "
                 "hjb, direct, none")
      ->check(CLI::IsMember({"auto", "hjb", "direct", "none"}))
      ->capture_default_str();
  app.add_option("--trace-member", o.trace_member, "member whose paths go to timeseries.csv and the plots")
      ->capture_default_str()
      ->transform(whole_number_notation());
  app.add_flag("!--no-plots", o.plots, "write the CSV and JSON files only (no plots, no report.md)");
}

const std::vector<std::pair<std::string, std::string>>& controller_aliases() {
  static const std::vector<std::pair<std::string, std::string>> aliases = {
      {"LQG", "LQR@KB"},          {"ASRE-C", "ASRE@ASRE"}, {"POLYREG", "POLY3@state"},
      {"POLYCTL", "POLY3@POLY3"}, {"LINREG", "LQR@state"}, {"LINCTL", "LQR@KBL"}};
  return aliases;
}

}  // namespace kushner
