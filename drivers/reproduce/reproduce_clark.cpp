// `kushner reproduce clark-table-2.1`: seed 003's Example 1 (Table 2.1). Two runs: estimation/ (`compare`: the
// Kalman filter, Clark's fourth-order moment filter, his cheap approximations, the exact Bayes filter (grid) and
// the particle filter on the same truths) for the estimation-error column, and control/ (`control`: the Riccati
// controller with the state, KF and MOM over Clark's N = 1000 stages) for the performance column.
#include "drivers/control_command.hpp"
#include "drivers/filter_command.hpp"
#include "drivers/filter_options.hpp"
#include "drivers/reproduce/reproduce_examples.hpp"
#include "kernels/reference/discrete_grid_filter.hpp"
#include "models/clark_linear_model.hpp"

#include <cmath>
#include <cstdio>
#include <string>

namespace kushner {

namespace {

constexpr const char* table_filters = "KF,MOM,MOM-MID,MOM-LS,MOM-LINE,MOM-HYP,PF,EXACT";
constexpr long control_stages = 1000;  // Table 2.1's N

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
  ExampleResult result{ReproductionTable("clark-table-2.1"), "", nlohmann::json::object(), {"estimation", "control"}};

  // estimation/: the filters on the same truths, open loop (the control is known to every filter and shifts
  // truth and estimate alike: the estimation error does not depend on it).
  CompareOptions options = example_options(model.name, table_filters, settings.members, settings);
  options.particles = settings.particles;
  options.run.out = (out.path() / "estimation").string();
  options.plots = settings.plots;
  const OutputDirectory estimation_out(options.run.out, "--out");
  const TimeGrid grid = make_time_grid(options.run.T, options.run.dt, options.run.output_points);
  const nlohmann::json estimation =
      run_compare_command(model, options, filter_option_values(options), grid, context, estimation_out);
  result.summary["runs"]["estimation"] = estimation;
  const nlohmann::json& f = estimation["filters"];
  const double T = settings.T;
  const char* reading = "mean over k = 1..T and members of (x[k] - x_hat[k])^2 (open loop: the known control shifts "
                        "truth and estimate alike)";
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
  if (result.table.verdict("MOM/estimation_error") != reproduces)
    result.table.explain("MOM/estimation_error",
                         "MOM here is (2.13)-(2.17) with exact predicted moments and Bayes' rule by quadrature, between "
                         "KF and the exact Bayes filter (EXACT); the printed 0.138 is not reached by it");

  // control/: the Riccati controller (Q = R = 1, D = 0, the last stage's Q x[N]^2 as the terminal term) with the
  // state, KF and MOM over N = 1000 stages, on common random numbers.
  ControlOptions control;
  control.run.model = model.name;
  control.run.members = settings.members;
  control.run.T = static_cast<double>(control_stages);
  control.run.dt = 1.0;
  control.run.seed = settings.seed;
  control.run.quiet = settings.quiet;
  control.run.out = (out.path() / "control").string();
  control.controllers = "LQR@state,LQR@KF,LQR@MOM";
  control.cost = {"F=1", "Q=1", "R=1"};
  control.reference = "none";
  control.plots = settings.plots;
  const TimeGrid control_grid = make_time_grid(control.run.T, 1.0, 200);
  const nlohmann::json loops =
      run_control_model(model, control, filter_option_values(control), control_grid, context, false);
  result.summary["runs"]["control"] = loops;
  // Clark's J (2.3) carries 1/2; the column header "(6x10^-3)" is read as a factor applied to the printed numbers
  // (the thesis does not say; the verdict tests this reading).
  for (const auto& [key, controller] : {std::pair<const char*, const char*>{"KF/performance", "LQR@KF"},
                                        std::pair<const char*, const char*>{"MOM/performance", "LQR@MOM"}}) {
    const nlohmann::json& c = loops["controllers"][controller];
    const double scale = 0.5 * 6e-3;  // Clark's 1/2, and the header's 6 x 10^-3 read as a factor
    result.table.add(key, scale * c["J"].get<double>(), scale * c["J_se"].get<double>(),
                     "(1/2) J x 6e-3, J = sum over N = 1000 stages of x^2 + u^2 (ours, `kushner control`) under the "
                     "Riccati controller; the header's (6x10^-3) read as a factor applied to the printed column");
  }
  char sizes[320];
  std::snprintf(sizes, sizeof sizes,
                "%ld members, T = %g steps, %d particles per member, seed %lld; EXACT is the grid Bayes filter "
                "(%d cells per member, exact cell masses from the noises' CDFs); control/: %ld stages",
                settings.members, settings.T, settings.particles, settings.seed,
                DiscreteGridFilter<Kokkos::DefaultHostExecutionSpace, ClarkLinearModel>::default_cells, control_stages);
  result.notes =
      "- Model: x[k+1] = 0.1 x[k] + u[k] + w[k], z[k+1] = x[k+1] + v[k+1], w with density (11/2) w^10 on (-1, 1), v "
      "uniform on (-1, 1) (003 (2.22)-(2.23)). x[0] is not stated: ours x[0] = 0, known to every filter.\n- Runs: " +
      std::string(sizes) +
      ".\n- The estimation error column is read as the steady-state mean squared error: the Kalman filter's printed "
      "0.240 is its steady-state error variance (P = 0.2394 for Var w = 11/13, Var v = 1/3). MOM is Clark's "
      "moment filter of order M = 4 ((2.13)-(2.17)); MOM-MID, -LS, -LINE, -HYP are his approximations (2.20), "
      "(2.28)-(2.30), shown in his figures only.\n- The performance column: the Riccati controller (2.5)-(2.7) "
      "with KF and with MOM in closed loop (control/); Clark finds it insensitive to the estimator for D = 0 "
      "(5.117 vs 5.111), and so do we (control/summary.json: paired differences).\n";
  return result;
}

}  // namespace kushner
