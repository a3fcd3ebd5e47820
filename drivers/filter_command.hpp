#pragma once
// `kushner filter` and `kushner compare` for one model type: defined once (filter_command_impl.hpp) and
// compiled in a few translation units, each for some of the models, so that the banks of all models build in
// parallel. `filter` is `compare` without trajectories, density snapshots, plots and report.
#include "drivers/checkpoint_file.hpp"
#include "drivers/filter_options.hpp"
#include "drivers/output_directory.hpp"
#include "drivers/run_metadata.hpp"
#include "drivers/run_options.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace kushner {

/// InputError (one line) for anything the run cannot do with this model: unknown or unsupported filters,
/// particle-filter settings, trajectory members or density times out of range. Returns the filters in report
/// order. Call before opening the output directory, so that a refused run writes nothing.
template <class Model>
std::vector<std::string> check_compare_options(const Model& model, const CompareOptions& options,
                                               const OptionValues& settings);

/// Runs truths, filters, particle filter and exact filter as `options` asks, writes into `out` summary.json,
/// timeseries.csv and, as asked, trajectories.csv, density.csv, the plots and report.md; returns the summary.
/// With options.checkpoints it saves checkpoints into `out` and continues from `resume` when given
/// (drivers/checkpoint_file.hpp). Needs Kokkos initialized (KokkosSession).
template <class Model>
nlohmann::json run_compare_command(const Model& model, const CompareOptions& options, const OptionValues& settings,
                                   const TimeGrid& grid, const RunContext& context, const OutputDirectory& out,
                                   const Checkpoint* resume = nullptr);

/// run_compare_command with the truths following `truth_model`, a model of the same type with other parameters
/// (`kushner reproduce clark-table-4.3` gives the filters a noise law the truths do not have). Compiled with the
/// command, so a caller compiles no bank of its own.
template <class Model>
nlohmann::json run_compare_with_truth_parameters(const Model& truth_model, const Model& model,
                                                 const CompareOptions& options, const OptionValues& settings,
                                                 const TimeGrid& grid, const RunContext& context,
                                                 const OutputDirectory& out);

}  // namespace kushner
