#pragma once
#include "drivers/backend.hpp"
#include "drivers/csv.hpp"
#include "drivers/filter_command.hpp"
#include "drivers/filter_run.hpp"
#include "drivers/filter_selection.hpp"
#include "drivers/output_directory.hpp"
#include "models/parameters.hpp"

#include <algorithm>
#include <string>

namespace kushner {

namespace detail {

inline std::string filter_timeseries_csv(const FilterReport& report, const RunContext& context) {
  std::string csv = csv_comment(context) + "t,filter,rmse_truth,rmse_truth_se,nees,nees_se,diverged";
  csv += report.has_reference ? ",rmse_ref\n" : "\n";
  for (std::size_t r = 0; r < report.times.size(); ++r)
    for (std::size_t f = 0; f < report.filters.size(); ++f) {
      const FilterSnapshot& s = report.series[r][f];
      csv += format_number(report.times[r]) + "," + report.filters[f] + "," + format_number(s.rmse_truth) + "," +
             format_number(s.rmse_truth_se) + "," + format_number(s.nees) + "," + format_number(s.nees_se) + "," +
             std::to_string(s.diverged);
      csv += report.has_reference ? "," + format_number(s.rmse_ref) + "\n" : "\n";
    }
  return csv;
}

template <class Model>
nlohmann::json filter_summary(const FilterReport& report, const FilterConfig& config) {
  nlohmann::json filters = nlohmann::json::object();
  for (std::size_t f = 0; f < report.filters.size(); ++f) {
    const FilterScores& s = report.scores[f];
    nlohmann::json j = {{"rmse_truth", s.rmse_truth.value},
                        {"rmse_truth_se", s.rmse_truth.standard_error},
                        {"nees", s.nees.value},
                        {"nees_se", s.nees.standard_error},
                        {"nees_members", s.nees.members},
                        {"diverged", s.diverged},
                        {"diverged_not_positive_definite", s.not_positive_definite},
                        {"diverged_non_finite", s.non_finite},
                        {"members_scored", s.rmse_truth.members}};
    if (report.has_reference) {
      j["rmse_ref"] = s.rmse_ref.value;
      j["rmse_ref_se"] = s.rmse_ref.standard_error;
    }
    if (report.filters[f] == "QLF") {
      const Expectations e = resolve_qlf_expectations<Model>(config.qlf_expectations);
      j["expectations"] = e == Expectations::closed ? "closed" : "cubature";
      if (e == Expectations::cubature) j["gh_nodes"] = config.gh_nodes;
    }
    if (report.filters[f] == "ASRE")
      j["iterations"] = {{"mean", report.asre.mean},
                         {"min", report.asre.min},
                         {"max", report.asre.max},
                         {"not_converged", report.asre.not_converged},
                         {"diverged", report.asre.diverged},
                         {"tolerance", config.asre_tolerance},
                         {"max_iterations", config.asre_max_iterations}};
    filters[report.filters[f]] = j;
  }
  return filters;
}

}  // namespace detail

template <class Model>
void run_filter_command(const Model& model, const FilterOptions& options, const FilterConfig& config,
                        const TimeGrid& grid, const RunContext& context) {
  const std::vector<std::string> filters = select_filters<Model>(options.filters);
  if (std::find(filters.begin(), filters.end(), "QLF") != filters.end())
    resolve_qlf_expectations<Model>(config.qlf_expectations);
  const OutputDirectory out(options.run.out, "--out");
  KokkosSession kokkos;
  with_backend(context.backend, [&](const auto& space) {
    const bool asre = std::find(filters.begin(), filters.end(), "ASRE") != filters.end();
    Progress progress("filter", grid.steps * (asre ? 3 : 1), !options.run.quiet);
    const FilterReport report =
        run_filters(space, model, model, options.run.members, static_cast<std::uint32_t>(options.run.seed), grid,
                    filters, config, nullptr, &progress);
    nlohmann::json summary = run_metadata(context);
    summary["model"] = {
        {"name", Model::name}, {"state_dim", Model::state_dim}, {"parameters", parameter_values(model)}};
    summary["members"] = options.run.members;
    summary["T"] = options.run.T;
    summary["dt"] = options.run.dt;
    summary["steps"] = grid.steps;
    summary["filters"] = detail::filter_summary<Model>(report, config);
    summary["filter_order"] = report.filters;
    summary["truths_escaped"] = report.truths_escaped;
    summary["files"] = {"summary.json", "timeseries.csv"};
    out.write("timeseries.csv", detail::filter_timeseries_csv(report, context));
    out.write("summary.json", summary.dump(2) + "\n");
  });
}

}  // namespace kushner
