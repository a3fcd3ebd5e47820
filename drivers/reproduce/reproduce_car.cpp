// `kushner reproduce basin-car-filter`: seed 002's automotive filter tables (L1505-1523).
#include "drivers/filter_command_impl.hpp"
#include "drivers/reproduce/reproduce_examples.hpp"
#include "engine/printed_car_filter.hpp"
#include "engine/prior_line_reference.hpp"
#include "models/car_model.hpp"

#include <cstdio>
#include <memory>
#include <string>

namespace kushner {

namespace {

/// One table of the paper: the truths follow `truth` (the Taylor model (20) or the original system (18)), with
/// the observation noises realized as sin t; KBL (= (22)) and POLY3 (the general (9)-(10)) run on the Taylor
/// model, beside them (21) as printed and the exact conditional mean of the Taylor model.
template <class TruthModel>
nlohmann::json run_table(const TruthModel& truth, const CarTaylor3Model& model, const ReproduceSettings& settings,
                         const RunContext& context, const OutputDirectory& out) {
  CompareOptions options = example_options(model.name, "KBL,POLY3", 1, settings);
  options.plots = settings.plots;  // each table's run draws its own figures
  const TimeGrid grid = make_time_grid(options.run.T, options.run.dt, options.run.output_points);
  const auto make_extras = [&](const auto& space) {
    using ExecSpace = std::decay_t<decltype(space)>;
    ExtraEstimators<ExecSpace> extra;
    extra.push_back(std::make_unique<PriorLineReference<ExecSpace, CarTaylor3Model>>(space, model, 1));
    extra.push_back(std::make_unique<PrintedCarFilter<ExecSpace>>(space, model, 1));
    return extra;
  };
  return run_compare_with_truth(truth, model, options, filter_option_values(options), grid, context, out, make_extras);
}

}  // namespace

ExampleResult reproduce_basin_car_filter(const ReproduceSettings& settings, const RunContext& context,
                                         const OutputDirectory& out) {
  const CarTaylor3Model model;  // v = l = 1, u = 0.05, m(0) = (10, 0.1), P(0) = [[100, 10], [10, 1]], V = I
  ExampleResult result{ReproductionTable("basin-car-filter"), "", nlohmann::json::object(), {"taylor", "tan"}};
  const OutputDirectory taylor_out(out.path() / "taylor", "--out");
  const OutputDirectory tan_out(out.path() / "tan", "--out");
  CarTaylor3Model taylor = model;
  taylor.sine_observation_noise = 1.0;
  result.summary["runs"]["taylor"] = run_table(taylor, model, settings, context, taylor_out);
  CarModel tan;
  static_cast<CarBase&>(tan) = taylor;
  result.summary["runs"]["tan"] = run_table(tan, model, settings, context, tan_out);

  const std::string truth_reading =
      "truth by Euler steps of the same dt from phi(0) = delta(0) = 0 with u = 0.05: delta(20) = 0.05 * 20 = 1 in "
      "both systems";
  const std::string taylor_phi_reading =
      "Taylor model (20) as printed, v = l = 1: phi(20) = 0.025 * 20^2 + 0.05^3 * 20^4 / 12 = 11.67; no reading of "
      "(20) with the stated parameters gives 5 (the integral of delta^3 alone, (20) without its linear term and "
      "its 1/3, gives exactly 5)";
  const std::string kb_reading =
      "KBL = (22) (Kalman-Bucy of the model linearized at 0), gain P as printed (V = I), dz = (x + sin t) dt";
  const std::string poly3_reading =
      "POLY3 = the general (9)-(10) for the Taylor model; differs from (21) as printed by the factor m_delta in "
      "3 p_dd m_delta and the term (v/l) p_dd^2 in dp_fd";
  const std::string printed_reading =
      "(21) as printed: (v/3l)(3 p_dd + m_delta^3) in dm_phi, no (v/l) p_dd^2 in dp_fd; gain P (V = I)";
  const std::string exact_reading =
      "exact conditional mean of the Taylor model given these observations (prior-line quadrature; q = 0, rank-1 "
      "P(0)), the reference of rmse_ref";
  std::string findings;
  for (const char* system : {"taylor", "tan"}) {
    const std::string s = system;
    const TerminalValues end = terminal_values(s == "taylor" ? taylor_out : tan_out, 0);
    for (const char* column : {"KB", "POLY3"}) {
      const std::string c = column;
      result.table.add(s + "/" + c + "/phi", end.value("truth", 0), 0.0,
                       s == "taylor" ? taylor_phi_reading
                                     : "original system (18): phi(20) = -ln(cos 1) / 0.05 = 12.31 (exact), Euler");
      result.table.add(s + "/" + c + "/delta", end.value("truth", 1), 0.0, truth_reading);
      const std::string series = c == "KB" ? "KBL" : "POLY3";
      result.table.add(s + "/" + c + "/m_phi", end.value(series, 0), 0.0, c == "KB" ? kb_reading : poly3_reading);
      result.table.add(s + "/" + c + "/m_delta", end.value(series, 1), 0.0, c == "KB" ? kb_reading : poly3_reading);
    }
    result.table.add(s + "/POLY3-21/m_phi", end.value("POLY3-21", 0), 0.0, printed_reading);
    result.table.add(s + "/POLY3-21/m_delta", end.value("POLY3-21", 1), 0.0, printed_reading);
    result.table.add(s + "/EXACT/m_phi", end.value("EXACT", 0), 0.0, exact_reading);
    result.table.add(s + "/EXACT/m_delta", end.value("EXACT", 1), 0.0, exact_reading);

    const nlohmann::json& filters = result.summary["runs"][s]["filters"];
    char line[640];
    std::snprintf(line, sizeof line,
                  "- `%s/`: truth (%.4g, %.4g), exact conditional mean (%.4g, %.4g), KBL (%.4g, %.4g), POLY3 (%.4g, "
                  "%.4g), (21) as printed (%.4g, %.4g) at T. RMS distance to the exact conditional mean over the run "
                  "(rmse_ref): POLY3 %.3g, KBL %.3g, (21) as printed %.3g.\n",
                  system, end.value("truth", 0), end.value("truth", 1), end.value("EXACT", 0), end.value("EXACT", 1),
                  end.value("KBL", 0), end.value("KBL", 1), end.value("POLY3", 0), end.value("POLY3", 1),
                  end.value("POLY3-21", 0), end.value("POLY3-21", 1), filters["POLY3"]["rmse_ref"].get<double>(),
                  filters["KBL"]["rmse_ref"].get<double>(), filters["POLY3-21"]["rmse_ref"].get<double>());
    findings += line;
  }

  char sizes[256];
  std::snprintf(sizes, sizeof sizes, "T = %g, dt = %g (%ld steps), one member (the run is deterministic)", settings.T,
                settings.dt, static_cast<long>(settings.T / settings.dt + 0.5));
  result.notes =
      std::string("- Runs: `taylor/` (truth: the Taylor model (20)) and `tan/` (truth: the original system (18)), ") +
      sizes +
      ". The filters run on the Taylor model (20), as in the paper: KBL (its equations (22)), POLY3 (the general "
      "degree-3 filter (9)-(10)) and POLY3-21 (its component equations (21) exactly as printed).\n"
      "- Observations: dz = x dt + sin t dt on both components, the paper's \"noises realized as sin t\" (002 "
      "L1505); the filters take them as white noise of unit intensity (V = I), which is what the printed gain P "
      "in (21)-(22) means. No process noise; the truth starts at 0, the filters at m(0) = (10, 0.1) with the "
      "singular P(0) = [[100, 10], [10, 1]] (002 L1505).\n"
      "- Reference: no particle filter (without process noise its resampled particles never spread again and the "
      "posterior is a point on the flow of the prior's line, about 1/100 of the prior's width at T: a bootstrap "
      "filter would keep about 1% of its particles). EXACT is the exact conditional mean of the filters' model "
      "instead: the rank-1 prior puts x(0) on a line, the dynamics are deterministic, so the posterior is a "
      "one-dimensional integral over that line, computed by quadrature (its error estimate is in summary.json). "
      "For the `tan` run it is the conditional mean under the Taylor model, not under the true system.\n"
      "- Why every estimate stays far from the truth: P(0) has rank 1, so the filters' model puts x(0) on the line "
      "(10, 0.1) + s (10, 1), which misses the truth's x(0) = 0 (s = -1 gives (0, -0.9)). Without process noise "
      "the model's states stay on the flow of that line, KBL's and POLY3's P keep rank 1, and even the exact "
      "conditional mean, concentrated on that flow, stays far from the truth.\n" +
      findings +
      "- Verdicts (table below): the original system's truth and the Kalman-Bucy column of table 2 reproduce, which "
      "also confirms this reading of the observations and the gain. The Taylor model's printed truth phi(20) = 5 "
      "does not (the model (20) gives 11.67 from the stated data), and with it none of table 1's filter values; "
      "the polynomial filter's values do not reproduce in either table, under the general equations or under (21) "
      "as printed; they lie close to the paper's printed truths, closer than even the exact conditional mean of the "
      "filters' model comes to the truth. Nothing was tuned.\n";
  return result;
}

}  // namespace kushner
