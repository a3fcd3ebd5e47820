#include "models/registry.hpp"

#include <algorithm>

namespace kushner {

#define KUSHNER_CONFIGURED_MODEL(Type) \
  template Type configured_model<Type>(Type, const std::vector<std::pair<std::string, std::string>>&);
KUSHNER_CONTINUOUS_MODELS(KUSHNER_CONFIGURED_MODEL)
KUSHNER_DISCRETE_MODELS(KUSHNER_CONFIGURED_MODEL)
KUSHNER_FILE_MODELS(KUSHNER_CONFIGURED_MODEL)
#undef KUSHNER_CONFIGURED_MODEL

std::vector<std::string> model_names() {
  std::vector<std::string> names;
  detail::for_each_model_type([&](auto* tag) {
    using Model = std::remove_pointer_t<decltype(tag)>;
    if (std::find(names.begin(), names.end(), Model::name) == names.end()) names.emplace_back(Model::name);
  });
  std::sort(names.begin(), names.end());
  return names;
}

nlohmann::json describe_models() {
  nlohmann::json models = nlohmann::json::array();
  detail::for_each_model_type([&](auto* tag) {
    using Model = std::remove_pointer_t<decltype(tag)>;
    if constexpr (dimension_choice<Model>::selectable) {
      if (Model::state_dim != dimension_choice<Model>::default_dim) return;  // listed once, at its default
    }
    Model model;
    ParameterRecorder recorder;
    model.parameters(recorder);
    nlohmann::json parameters = nlohmann::json::array();
    if constexpr (dimension_choice<Model>::selectable)
      parameters.push_back(
          {{"name", "dim"}, {"default", Model::state_dim}, {"description", "state dimension (1, 2 or 3)"}});
    for (const auto& e : recorder.entries())
      parameters.push_back({{"name", e.name}, {"default", e.value}, {"description", e.description}});
    models.push_back({{"name", Model::name},
                      {"description", Model::description},
                      {"time", Model::discrete_time ? "discrete" : "continuous"},
                      {"state_dim", Model::state_dim},
                      {"obs_dim", Model::obs_dim},
                      {"parameters", parameters}});
  });
  std::sort(models.begin(), models.end(),
            [](const nlohmann::json& a, const nlohmann::json& b) { return a["name"] < b["name"]; });
  return models;
}

}  // namespace kushner
