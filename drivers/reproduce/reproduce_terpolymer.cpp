// `kushner reproduce basin-terpolymer`: seed 002's ACC03 terpolymerization example (figure only).
#include "drivers/filter_command_impl.hpp"
#include "drivers/reproduce/reproduce_examples.hpp"
#include "models/terpolymer_model.hpp"

#include <cmath>
#include <cstdio>
#include <string>

namespace kushner {

ExampleResult reproduce_basin_terpolymer(const ReproduceSettings& settings, const RunContext& context,
                                         const OutputDirectory& out) {
  const TerpolymerModel model;  // all parameters 1, x(0) = 0, m(0) = 0.5, P(0) = I, q = 0, V = I
  const CompareOptions options = example_options(model.name, "BILIN,MIXED,KBL", 1, settings);
  const TimeGrid grid = make_time_grid(options.run.T, options.run.dt, options.run.output_points);
  ExampleResult result{ReproductionTable("basin-terpolymer"), "", {}, {}};
  TerpolymerModel truth = model;
  truth.sine_observation_noise = 1.0;
  result.summary =
      run_compare_with_truth_parameters(truth, model, options, filter_option_values(options), grid, context, out);

  const nlohmann::json& f = result.summary["filters"];
  const TerminalValues end = terminal_values(out, 0);
  const char* readings[] = {
      "BILIN = the bilinear filter (13)-(14) in the tensor form, i.e. (16)-(17) with all 55 variance equations",
      "MIXED = BILIN's estimate equations (16) with KBL's variance equations (21) (L1795)",
      "KBL = Kalman-Bucy filter of the linearized model (20)-(21): a0 + a1 x, the bilinear terms dropped"};
  const char* names[] = {"BILIN", "MIXED", "KBL"};
  double rmse[3];
  for (int i = 0; i < 3; ++i) {
    const std::string name = names[i];
    rmse[i] = f[name]["rmse_truth"].get<double>();
    result.table.add(name + "/rmse_truth", rmse[i], 0.0, readings[i]);
    double squared = 0.0;
    for (int c = 0; c < TerpolymerModel::state_dim; ++c) {
      const double e = end.value(name, c) - end.value("truth", c);
      squared += e * e;
    }
    result.table.add(name + "/error_T", std::sqrt(squared), 0.0, readings[i]);
  }
  const bool bilinear_best = rmse[0] < rmse[1] && rmse[0] < rmse[2];
  char ranking[160];
  std::snprintf(ranking, sizeof ranking, "rmse_truth BILIN %.4g, MIXED %.4g, KBL %.4g", rmse[0], rmse[1], rmse[2]);
  result.table.add_text("claim/bilinear_best", ranking, bilinear_best,
                        "\"best estimate\" read as the smallest RMS error to the truth over [0, T] (time points 0, "
                        "dt, ..., T, all ten states)");
  char sizes[200];
  std::snprintf(sizes, sizeof sizes, "T = %g (ours: the paper states no horizon), dt = %g, one member (deterministic)",
                settings.T, settings.dt);
  result.notes =
      std::string(
          "- Model: the ten bilinear reactor equations (18) with every parameter 1, all states observed, no process "
          "noise, truth from 0, filters from m(0) = 0.5, P(0) = I (002 L1739-1770). Observations dy = x dt + sin t "
          "dt on every component: the paper's \"white Gaussian noises ... realized as sinusoidal signals\" (L1770); "
          "the filters take them as white noise of unit intensity (V = I: the printed gain is P).\n- Run: ") +
      sizes +
      ". No reference estimator: the particle filter is limited to 4 states, and without process noise a "
      "10-dimensional prior would leave a bootstrap filter almost no effective particles.\n"
      "- The paper shows Figure 1 only and states that the bilinear filter is the best of the three (L1797): the "
      "claim is the one row with a verdict.\n";
  return result;
}

}  // namespace kushner
