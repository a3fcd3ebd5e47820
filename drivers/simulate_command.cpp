#include "drivers/commands.hpp"
#include "drivers/csv.hpp"
#include "drivers/output_directory.hpp"
#include "drivers/progress.hpp"
#include "drivers/run_model.hpp"
#include "engine/backend.hpp"
#include "engine/truth_bank.hpp"

namespace kushner {

namespace {

template <class Model>
std::string timeseries_csv(const MomentSeries& series, const RunContext& context) {
  std::string csv = csv_comment(context) + "t";
  for (int i = 1; i <= Model::state_dim; ++i) csv += ",mean_x" + std::to_string(i) + ",var_x" + std::to_string(i);
  csv += ",diverged\n";
  for (std::size_t r = 0; r < series.times.size(); ++r) {
    csv += format_number(series.times[r]);
    for (int i = 0; i < Model::state_dim; ++i)
      csv += "," + format_number(series.moments[r].mean[i]) + "," + format_number(series.moments[r].variance[i]);
    csv += "," + std::to_string(series.moments[r].non_finite) + "\n";
  }
  return csv;
}

}  // namespace

int run_simulate(const RunOptions& given, const RunContext& context) {
  validate_run_options(given);
  with_run_model(given.model, given.model_file, given.sets, [&](const auto& model) {
    using Model = std::decay_t<decltype(model)>;
    const RunOptions options = options_for_model_time(given, Model::discrete_time);
    const TimeGrid grid = make_time_grid(options.T, options.dt, options.output_points);
    const OutputDirectory out(options.out, "--out");
    KokkosSession kokkos(context.backend);
    with_backend(context.backend, [&](const auto& space) {
      Progress progress("simulate", grid.steps, !options.quiet);
      const MomentSeries series =
          simulate_ensemble(space, model, options.members, static_cast<std::uint32_t>(options.seed), grid,
                            [&](long done) { progress.update(done); });
      nlohmann::json summary = run_metadata(context);
      summary["model"] = model_summary(model);
      summary["members"] = options.members;
      summary["T"] = options.T;
      summary["dt"] = options.dt;
      summary["steps"] = grid.steps;
      summary["mean_final"] = series.moments.back().mean;
      summary["var_final"] = series.moments.back().variance;
      summary["diverged"] = series.moments.back().non_finite;  // paths that escaped: left out of the moments
      summary["files"] = {"summary.json", "timeseries.csv"};
      summary["timing"] = timing_json(series.step_loop_seconds, static_cast<double>(options.members) * grid.steps);
      out.write_all(
          {{"timeseries.csv", timeseries_csv<Model>(series, context)}, {"summary.json", summary.dump(2) + "\n"}});
    });
  });
  return 0;
}

}  // namespace kushner
