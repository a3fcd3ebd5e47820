#include "drivers/commands.hpp"
#include "drivers/filter_options.hpp"
#include "drivers/filter_selection.hpp"
#include "engine/backend_session.hpp"
#include "models/registry.hpp"

#include <cmath>
#include <iostream>
#include <map>
#include <variant>

namespace kushner {

int run_models(bool json) {
  const nlohmann::json models = describe_models();
  if (json) {
    std::cout << models.dump(2) << "\n";
    return 0;
  }
  for (const auto& m : models) {
    std::cout << m["name"].get<std::string>() << "  (" << m["time"].get<std::string>() << " time, state_dim "
              << m["state_dim"] << ", obs_dim " << m["obs_dim"] << ")\n    " << m["description"].get<std::string>()
              << "\n";
    for (const auto& p : m["parameters"])
      std::cout << "    --set " << p["name"].get<std::string>() << "=" << p["default"].dump() << "  "
                << p["description"].get<std::string>() << "\n";
  }
  std::cout << "--model-file FILE instead of --model: a polynomial model of your own (state_dim 1..3, drift or "
               "discrete-time transition of degree <= 4, observation of degree <= 3) from a TOML file; README, "
               "\"Models\"; examples in models/examples/\n";
  return 0;
}

int run_filters_list(bool json) {
  // filter name -> (supported models, refused models with the reason), in report order
  const std::vector<std::string> names = all_filter_names();
  std::map<std::string, nlohmann::json> supported, refused;
  std::map<std::string, std::string> descriptions;
  std::map<std::string, nlohmann::json> options;
  detail::for_each_model_type([&](auto* tag) {
    using Model = std::remove_pointer_t<decltype(tag)>;
    if constexpr (listed_once<Model>()) {  // a model's own time's filters (the other time's are never its)
      for (const auto& f : filter_support(Model{})) {
        descriptions[f.name] = f.description;
        options[f.name] = nlohmann::json::array();
        for (const OptionSpec& o : f.options) {
          nlohmann::json option = {{"name", option_flag(o.name)}, {"help", o.help}};
          std::visit([&](const auto& v) { option["default"] = v; }, o.default_value);
          if (o.kind == OptionSpec::Kind::choice) option["choices"] = o.choices;
          if (o.kind != OptionSpec::Kind::choice && std::isfinite(o.min)) option["min"] = o.min;
          if (o.kind != OptionSpec::Kind::choice && std::isfinite(o.max)) option["max"] = o.max;
          if (o.positive) option["positive"] = true;
          options[f.name].push_back(option);
        }
        if (f.unsupported == nullptr)
          supported[f.name].push_back(Model::name);
        else
          refused[f.name].push_back({{"model", Model::name}, {"reason", f.unsupported}});
      }
    }
  });
  nlohmann::json list = nlohmann::json::array();
  for (const auto& name : names) {
    nlohmann::json s = supported.count(name) ? supported[name] : nlohmann::json::array();
    nlohmann::json r = refused.count(name) ? refused[name] : nlohmann::json::array();
    std::sort(s.begin(), s.end());
    list.push_back({{"name", name},
                    {"description", descriptions[name]},
                    {"models", s},
                    {"refuses", r},
                    {"options", options[name]}});
  }
  if (json) {
    std::cout << list.dump(2) << "\n";
    return 0;
  }
  for (const auto& f : list) {
    std::cout << f["name"].get<std::string>() << "  " << f["description"].get<std::string>() << "\n    models:";
    for (const auto& m : f["models"]) std::cout << " " << m.get<std::string>();
    std::cout << "\n";
    for (const auto& r : f["refuses"])
      std::cout << "    not " << r["model"].get<std::string>() << ": " << r["reason"].get<std::string>() << "\n";
    for (const auto& o : f["options"])
      std::cout << "    " << o["name"].get<std::string>() << " (default " << o["default"].dump()
                << "): " << o["help"].get<std::string>() << "\n";
  }
  return 0;
}

int run_version() {
  const std::string backend = selected_backend();
  KokkosSession kokkos(backend);
  const BackendDescription b = describe_backend(backend);
  std::cout << version_string() << "\nKokkos " << b.kokkos << "\nbackend: " << backend;
  if (b.threads > 0) std::cout << " (" << b.threads << " threads)";
  if (!b.device.empty()) std::cout << " (device: " << b.device << ")";
  std::cout << "\navailable backends:";
  for (const auto& n : available_backends()) std::cout << " " << n;
  std::cout << " (select with KUSHNER_BACKEND)\n";
  return 0;
}

}  // namespace kushner
