// `kushner reproduce clark-table-2.1`: seed 003's Example 1 (Table 2.1), the estimation-error column: the
// Kalman filter, Clark's fourth-order moment filter, his cheap approximations, the exact Bayes filter (grid)
// and the particle filter on the same truths.
#include "drivers/filter_command.hpp"
#include "drivers/filter_options.hpp"
#include "drivers/reproduce/reproduce_examples.hpp"
#include "models/clark_linear_model.hpp"

#include <cmath>
#include <cstdio>
#include <string>

namespace kushner {

namespace {

constexpr const char* table_filters = "KF,MOM,MOM-MID,MOM-LS,MOM-LINE,MOM-HYP,PF,EXACT";

struct MeanSquare {
  double value, standard_error;
};

/// The steady-state mean squared error from a run's time-and-ensemble rmse_truth over k = 0..T: x[0] is known
/// (error 0 at k = 0), so the mean over k = 1..T is rmse^2 (T + 1) / T; its standard error by the delta method.
MeanSquare mean_squared_error(const nlohmann::json& filter, double T) {
  const double rmse = filter["rmse_truth"].get<double>(), se = filter["rmse_truth_se"].get<double>();
  const double scale = (T + 1.0) / T;
  return {rmse * rmse * scale, 2.0 * rmse * se * scale};
}

}  // namespace

ExampleResult reproduce_clark_table_2_1(const ReproduceSettings& settings, const RunContext& context,
                                        const OutputDirectory& out) {
  KUSHNER_INPUT_REQUIRE(settings.dt == 1.0, "--dt: clark-table-2.1 is a discrete-time example (steps of 1)");
  const ClarkLinearModel model;  // a = 0.1, w: rho = 10 on (-1, 1), v uniform on (-1, 1), x[0] = 0 known
  CompareOptions options = example_options(model.name, table_filters, settings.members, settings);
  options.particles = settings.particles;
  const TimeGrid grid = make_time_grid(options.run.T, options.run.dt, options.run.output_points);
  ExampleResult result{ReproductionTable("clark-table-2.1"), "", {}, {}};
  result.summary = run_compare_command(model, options, filter_option_values(options), grid, context, out);
  const nlohmann::json& f = result.summary["filters"];
  const double T = settings.T;
  const char* reading = "mean over k = 1..T and members of (x[k] - x_hat[k])^2; the estimation error does not depend on "
                        "the (known) control for these shift-equivariant filters, so the open loop measures it";
  for (const char* name : {"KF", "MOM", "EXACT", "PF", "MOM-MID", "MOM-LS", "MOM-LINE", "MOM-HYP"}) {
    const MeanSquare e = mean_squared_error(f[name], T);
    result.table.add(std::string(name) + "/estimation_error", e.value, e.standard_error, reading);
  }
  const MeanSquare kf = mean_squared_error(f["KF"], T), bayes = mean_squared_error(f["EXACT"], T);
  const double separation = (kf.value - bayes.value) / std::hypot(kf.standard_error, bayes.standard_error);
  char text[160];
  std::snprintf(text, sizeof text, "%.1f standard errors (KF %.4f, Bayes %.4f)", separation, kf.value, bayes.value);
  result.table.add_text("bayes_below_kf", text, separation > 5.0,
                        "unpaired standard errors (conservative: the two errors are positively correlated)");
  const std::string no_loop = "discrete-time closed loop not built yet (issue 15 part 4): J not computed";
  result.table.add_none("KF/performance", "not computed", no_loop);
  result.table.add_none("MOM/performance", "not computed", no_loop);
  if (result.table.verdict("MOM/estimation_error") != reproduces)
    result.table.explain("MOM/estimation_error",
                         "our MOM is (2.13)-(2.17) with exact predicted moments and Bayes' rule by quadrature; the "
                         "printed 0.138 is below the exact Bayes filter's error in our runs only if the thesis' "
                         "filter or its error measure differ from ours (see EXACT)");
  char sizes[320];
  std::snprintf(sizes, sizeof sizes,
                "%ld members, T = %g steps, %d particles per member, seed %lld; EXACT is the grid Bayes filter "
                "(400 cells per member, exact cell masses from the noises' CDFs)",
                settings.members, settings.T, settings.particles, settings.seed);
  result.notes =
      "- Model: x[k+1] = 0.1 x[k] + u[k] + w[k], z[k+1] = x[k+1] + v[k+1], w with density (11/2) w^10 on (-1, 1), v "
      "uniform on (-1, 1) (003 (2.22)-(2.23)). x[0] is not stated: ours x[0] = 0, known to every filter.\n- Run: " +
      std::string(sizes) +
      ".\n- The estimation error column is read as the steady-state mean squared error: the Kalman filter's printed "
      "0.240 is its steady-state error variance (P = 0.2394 for Var w = 11/13, Var v = 1/3). MOM is Clark's "
      "moment filter of order M = 4 ((2.13)-(2.17)); MOM-MID, -LS, -LINE, -HYP are his approximations (2.20), "
      "(2.28)-(2.30), shown in his figures only.\n- The performance column needs the discrete-time Riccati loop "
      "(not built yet); Clark finds it insensitive to the estimator for D = 0 (5.117 vs 5.111).\n";
  return result;
}

}  // namespace kushner
