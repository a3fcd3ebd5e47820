// `kushner control`: controllers LAW@ESTIMATOR in closed loop on the bank (engine/control/control_run.hpp), scored by
// the expected cost with paired standard errors; summary.json, timeseries.csv, plots and report.md.
#include "drivers/commands.hpp"
#include "drivers/control_command_impl.hpp"

#include <cstdio>
#include <string>

namespace kushner {

using namespace control_detail;

int run_control_command(const ControlOptions& given, const RunContext& context) {
  validate_run_options(given.run);
  const OptionValues settings = filter_option_values(given);
  with_run_model(given.run.model, given.run.model_file, given.run.sets, [&](const auto& model) {
    using Model = std::decay_t<decltype(model)>;
    ControlOptions options = given;
    options.run = options_for_model_time(given.run, Model::discrete_time);
    const TimeGrid grid = make_time_grid(options.run.T, options.run.dt, options.run.output_points);
    run_control_model(model, options, settings, grid, context, /*own_kokkos=*/true);
  });
  return 0;
}

int run_controllers_list(bool json) {
  nlohmann::json j;
  j["laws"] = nlohmann::json::array();
  for (const auto& law : law_list()) j["laws"].push_back({{"name", law.name}, {"description", law.description}});
  j["aliases"] = nlohmann::json::object();
  for (const auto& [alias, meaning] : controller_aliases()) j["aliases"][alias] = meaning;
  j["models"] = nlohmann::json::object();
  detail::for_each_model_type([&](auto* tag) {
    using Model = std::remove_pointer_t<decltype(tag)>;
    if constexpr (ModelTraits<Model>::controlled && listed_once<Model>()) {
      const Model model;
      nlohmann::json entry;
      entry["estimators"] = known_estimators(model);
      entry["laws"] = nlohmann::json::object();
      for (const auto& law : law_list()) {
        const char* why = law_unsupported<Model>(law.name);
        entry["laws"][law.name] = why ? why : "supported";
      }
      j["models"][Model::name] = entry;
    }
  });
  if (json) {
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  std::printf("Controllers are LAW@ESTIMATOR: a gain law applied to an estimate of the state.\n\nLaws:\n");
  for (const auto& law : law_list()) std::printf("  %-8s %s\n", law.name.c_str(), law.description.c_str());
  std::printf(
      "\nEstimators: state (full information), any filter of the bank that supports the model, PF (the\n"
      "particle filter's posterior mean).\n\nAliases:\n");
  for (const auto& [alias, meaning] : controller_aliases())
    std::printf("  %-8s = %s\n", alias.c_str(), meaning.c_str());
  std::printf("\nModels with a control input:\n");
  for (const auto& [name, entry] : j["models"].items()) {
    std::string estimators, laws;
    for (const auto& e : entry["estimators"]) estimators += (estimators.empty() ? "" : ", ") + e.get<std::string>();
    for (const auto& [law, why] : entry["laws"].items())
      laws += (laws.empty() ? "" : ", ") + law + (why == "supported" ? "" : " (not: " + why.get<std::string>() + ")");
    std::printf("  %-17s laws: %s\n  %-17s estimators: %s\n", name.c_str(), laws.c_str(), "", estimators.c_str());
  }
  return 0;
}

}  // namespace kushner
