#pragma once
// The examples of `kushner reproduce`, one function each (each compiled in its own translation unit: their
// banks are separate template instantiations). Each runs the paper's experiment with the engine, writes the
// compare artefacts into the output directory (or one subdirectory per run when the paper has several) and
// fills the reproduction table from them; drivers/reproduce/reproduce_command.cpp writes the table, the
// report and prints it.
#include "drivers/filter_options.hpp"
#include "drivers/output_directory.hpp"
#include "drivers/reproduce/reproduction_table.hpp"
#include "drivers/run_metadata.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace kushner {

/// The sizes of a run after the command line's overrides of the example's defaults.
struct ReproduceSettings {
  double T = 0.0;
  long members = 0;
  long long seed = 1;
  int particles = 0;
  double dt = 0.0;
  bool quiet = false;
  bool plots = true;
};

/// The compare options an example starts from: the settings' sizes and seed, `filters` run on `members`
/// members, the first (up to) three members' trajectories recorded, and no plots (the command draws them once
/// the reproduction table is written).
inline CompareOptions example_options(const char* model, const char* filters, long members,
                                      const ReproduceSettings& settings) {
  CompareOptions options;
  options.run.model = model;
  options.run.members = members;
  options.run.T = settings.T;
  options.run.dt = settings.dt;
  options.run.seed = settings.seed;
  options.run.quiet = settings.quiet;
  options.filters = filters;
  options.trajectory_members.clear();
  for (long m = 0; m < 3 && m < members; ++m) options.trajectory_members.push_back(m);
  options.plots = false;
  return options;
}

struct ExampleResult {
  ReproductionTable table;
  std::string notes;              // markdown: what ran, with which sizes and readings
  nlohmann::json summary;         // one run: its compare summary; several: {"runs": {name: summary}}
  std::vector<std::string> runs;  // subdirectories holding the runs' artefacts; empty: the output directory itself
  // false: the example wrote no compare run (no timeseries.csv for the figures), so report.md is the table alone
  bool compare_report = true;
};

/// The terminal values of `trajectories.csv` (as `kushner compare` writes it) for `member`: (series, component)
/// -> estimate at the last time. KUSHNER_REQUIRE that the file exists and has that member.
struct TerminalValues {
  double t = 0.0;
  double value(const std::string& series, int component) const;
  std::vector<std::pair<std::string, std::vector<double>>> series;
};
TerminalValues terminal_values(const OutputDirectory& out, long member);

ExampleResult reproduce_sunahara_ex1(const ReproduceSettings& settings, const RunContext& context,
                                     const OutputDirectory& out);
ExampleResult reproduce_sunahara_ex2(const ReproduceSettings& settings, const RunContext& context,
                                     const OutputDirectory& out);
ExampleResult reproduce_basin_car_filter(const ReproduceSettings& settings, const RunContext& context,
                                         const OutputDirectory& out);
ExampleResult reproduce_basin_car_regulator(const ReproduceSettings& settings, const RunContext& context,
                                            const OutputDirectory& out);
ExampleResult reproduce_basin_regulator_enotes(const ReproduceSettings& settings, const RunContext& context,
                                               const OutputDirectory& out);
ExampleResult reproduce_basin_car_controller(const ReproduceSettings& settings, const RunContext& context,
                                             const OutputDirectory& out);
ExampleResult reproduce_basin_terpolymer(const ReproduceSettings& settings, const RunContext& context,
                                         const OutputDirectory& out);
ExampleResult reproduce_clark_table_2_1(const ReproduceSettings& settings, const RunContext& context,
                                        const OutputDirectory& out);
ExampleResult reproduce_clark_table_3_1(const ReproduceSettings& settings, const RunContext& context,
                                        const OutputDirectory& out);
ExampleResult reproduce_clark_table_4_3(const ReproduceSettings& settings, const RunContext& context,
                                        const OutputDirectory& out);
ExampleResult reproduce_tarushkin_attitude(const ReproduceSettings& settings, const RunContext& context,
                                           const OutputDirectory& out);

}  // namespace kushner
