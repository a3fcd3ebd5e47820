#include "drivers/reproduce/reproduce_options.hpp"

#include "drivers/whole_number_notation.hpp"

#include <CLI/CLI.hpp>

namespace kushner {

void add_reproduce_options(CLI::App& app, ReproduceOptions& o) {
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("name", o.example, "example: sunahara-ex1, sunahara-ex2, basin-car-filter, basin-terpolymer")
      ->required();
  app.add_option("--out", o.out, "output directory (created if missing)")->required();
  app.add_flag("--quiet", o.quiet, "no progress bar");
  app.add_flag("!--no-plots", o.plots, "write the CSV and JSON files only (no plots, no report.md)");
  app.add_option_function<long>(
         "--members", [&o](const long& v) { o.members = v; }, "ensemble members (stochastic examples; default 100)")
      ->transform(whole_number_notation());
  app.add_option_function<int>(
         "--particles", [&o](const int& v) { o.particles = v; },
         "particles per member of the reference (stochastic examples; default 1024)")
      ->transform(whole_number_notation());
  app.add_option_function<long long>(
         "--seed", [&o](const long long& v) { o.seed = v; },
         "random seed, 0 .. 4294967295 (stochastic examples; default 1)")
      ->transform(whole_number_notation());
  app.add_option_function<double>(
      "--dt", [&o](const double& v) { o.dt = v; }, "time step (default: the example's, see the README)");
}

}  // namespace kushner
