#include "drivers/filter_command.hpp"
#include "core/collectives.hpp"
#include "drivers/checkpoint_file.hpp"
#include "drivers/commands.hpp"
#include "drivers/run_model.hpp"
#include "engine/backend.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

namespace kushner {

namespace {

/// The metrics table on stdout: what a person running `compare` wants to see first.
void print_summary(const nlohmann::json& summary, const std::string& out) {
  const nlohmann::json& filters = summary["filters"];
  auto number = [](const nlohmann::json& j, const char* key) {
    return j.contains(key) && j[key].is_number() ? j[key].get<double>() : std::nan("");
  };
  std::printf("%-7s %22s %22s %16s %9s\n", "filter", "rmse_ref", "rmse_truth", "nees", "diverged");
  for (const auto& name : summary["filter_order"]) {
    const nlohmann::json& f = filters[name.get<std::string>()];
    char ref[32] = "           (reference)";
    if (f.contains("rmse_ref"))
      std::snprintf(ref, sizeof ref, "%11.4g +- %-7.2g", number(f, "rmse_ref"), number(f, "rmse_ref_se"));
    std::printf("%-7s %22s %11.4g +- %-7.2g %7.3g +- %-6.2g %9ld\n", name.get<std::string>().c_str(), ref,
                number(f, "rmse_truth"), number(f, "rmse_truth_se"), number(f, "nees"), number(f, "nees_se"),
                f["diverged"].get<long>());
  }
  if (summary.contains("plots_error"))
    std::fprintf(stderr, "kushner: warning: %s\n", summary["plots_error"].get<std::string>().c_str());
  if (summary.contains("timing")) print_timing(summary["timing"]);
  const bool report = std::any_of(summary["files"].begin(), summary["files"].end(),
                                  [](const nlohmann::json& f) { return f == "report.md"; });
  std::printf("written to %s/ (%s)\n", out.c_str(),
              summary.value("plots", false) ? "report.md, plots, CSV, JSON"
              : report                      ? "report.md, CSV, JSON"
                                            : "CSV, JSON");
}

/// InputError for --checkpoint-every values a run cannot use, and for a new run into a directory that holds an
/// unfinished run's checkpoint (which it would overwrite).
void check_checkpoint_options(const CompareOptions& options, const Checkpoint* resume) {
  if (options.checkpoint_every_given) {
    KUSHNER_INPUT_REQUIRE(std::isfinite(options.checkpoint_every) && options.checkpoint_every >= 0.0,
                          "--checkpoint-every: expected seconds >= 0, got " << options.checkpoint_every);
    KUSHNER_INPUT_REQUIRE(collective::ranks() == 1, "--checkpoint-every: runs over MPI ranks are not checkpointed ("
                                                        << collective::ranks() << " ranks)");
  }
  KUSHNER_INPUT_REQUIRE(
      resume != nullptr || !has_checkpoint(options.run.out),
      "--out: '" << options.run.out << "' holds the checkpoint of an unfinished run: continue it with `kushner resume "
                 << options.run.out << "`, or remove " << checkpoint_file_name << " there to start again");
}

int run_estimation(const CompareOptions& given, const RunContext& context, const Checkpoint* resume) {
  validate_run_options(given.run);
  check_checkpoint_options(given, resume);
  const OptionValues settings = filter_option_values(given);
  with_run_model(given.run.model, given.run.model_file, given.run.sets, [&](const auto& model) {
    using Model = std::decay_t<decltype(model)>;
    CompareOptions options = given;
    options.run = options_for_model_time(given.run, Model::discrete_time);
    options.checkpoints = collective::ranks() == 1;  // MPI ranks: no checkpoints, signals end the run
    const TimeGrid grid = make_time_grid(options.run.T, options.run.dt, options.run.output_points);
    check_compare_options<Model>(model, options, settings);  // before anything is written
    const OutputDirectory out(options.run.out, "--out");
    KokkosSession kokkos(context.backend);
    const nlohmann::json summary = run_compare_command(model, options, settings, grid, context, out, resume);
    if (options.plots && !options.run.quiet) print_summary(summary, options.run.out);
  });
  return 0;
}

}  // namespace

int run_filter(const FilterOptions& options, const RunContext& context, const Checkpoint* resume) {
  CompareOptions compare;
  static_cast<FilterOptions&>(compare) = options;
  compare.trajectory_members.clear();
  compare.plots = false;
  return run_estimation(compare, context, resume);
}

int run_compare(const CompareOptions& options, const RunContext& context, const Checkpoint* resume) {
  return run_estimation(options, context, resume);
}

}  // namespace kushner
