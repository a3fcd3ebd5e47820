#pragma once
// The subcommands of `kushner`. Each validates all its input before opening any output and throws
// InputError for bad input; command_line_main() turns that into one line on stderr and exit code 2.
#include "drivers/checkpoint_file.hpp"
#include "drivers/control_options.hpp"
#include "drivers/filter_options.hpp"
#include "drivers/reproduce/reproduce_options.hpp"
#include "drivers/run_metadata.hpp"
#include "drivers/run_options.hpp"

namespace kushner {

/// `kushner simulate`: the bank of truths; writes summary.json and timeseries.csv.
int run_simulate(const RunOptions& options, const RunContext& context);

/// `kushner filter`: the bank of truths and filters; writes summary.json and timeseries.csv. Saves checkpoints
/// (drivers/checkpoint_file.hpp) and continues from `resume` when given.
int run_filter(const FilterOptions& options, const RunContext& context, const Checkpoint* resume = nullptr);

/// `kushner compare`: `filter` with the particle reference by default, plus trajectories, density
/// snapshots, plots and report.md; checkpoints as `filter`.
int run_compare(const CompareOptions& options, const RunContext& context, const Checkpoint* resume = nullptr);

/// `kushner reproduce NAME`: a worked example of the seeds run by the engine, with compare's artefacts and a
/// table of the paper's numbers next to ours (reproduction.csv, reproduction.md, printed on stdout).
int run_reproduce(const ReproduceOptions& options, const RunContext& context);

/// `kushner control`: controllers LAW@ESTIMATOR in closed loop; writes summary.json, timeseries.csv, plots and
/// report.md.
int run_control_command(const ControlOptions& options, const RunContext& context);

/// `kushner controllers`: the gain laws, estimators, aliases and the models each law can control.
int run_controllers_list(bool json);

/// `kushner filters`: every filter and the models it supports (or why not).
int run_filters_list(bool json);

/// `kushner models`: the built-in models and their parameters.
int run_models(bool json);

/// `kushner --version`: versions, the backend in use and its threads or device.
int run_version();

}  // namespace kushner
