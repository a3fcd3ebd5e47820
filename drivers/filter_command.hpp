#pragma once
// `kushner filter` for one model type: defined once (filter_command_impl.hpp) and compiled in a few
// translation units, each for some of the models, so that the filter banks of all models build in parallel.
#include "drivers/filter_options.hpp"
#include "drivers/run_metadata.hpp"
#include "drivers/run_options.hpp"

namespace kushner {

/// Selects and checks the filters, opens the output directory, runs the bank, writes summary.json and
/// timeseries.csv.
template <class Model>
void run_filter_command(const Model& model, const FilterOptions& options, const FilterConfig& config,
                        const TimeGrid& grid, const RunContext& context);

}  // namespace kushner
