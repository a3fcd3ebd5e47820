#pragma once
// The one place where a model name becomes a type. Commands call with_model(name, sets, f): the model is
// built, its `--set key=value` assignments applied and checked, and f(model) called with the concrete type,
// so everything downstream is dispatched at compile time.
#include "core/errors.hpp"
#include "models/model_checks.hpp"
#include "models/model_list.hpp"
#include "models/parameters.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

namespace kushner {

/// Models whose state dimension is chosen on the command line (`--set dim=N`), and its default.
template <class Model>
struct dimension_choice {
  static constexpr bool selectable = false;
};
template <int N>
struct dimension_choice<LinearModel<N>> {
  static constexpr bool selectable = true;
  static constexpr int default_dim = 2;
};

/// Whether a listing of models (`kushner filters`, `kushner controllers`) shows this type: a name with several
/// dimensions is listed at its default.
template <class Model>
constexpr bool listed_once() {
  if constexpr (dimension_choice<Model>::selectable)
    return Model::state_dim == dimension_choice<Model>::default_dim;
  else
    return true;
}

namespace detail {

template <class Tuple, class F, std::size_t... I>
void for_each_type(F&& f, std::index_sequence<I...>) {
  (f(static_cast<std::tuple_element_t<I, Tuple>*>(nullptr)), ...);
}

/// Calls f(static_cast<Model*>(nullptr)) for every built-in model type.
template <class F>
void for_each_model_type(F&& f) {
  detail::for_each_type<BuiltinModels>(f, std::make_index_sequence<std::tuple_size_v<BuiltinModels>>{});
}

}  // namespace detail

/// Distinct model names, sorted, for messages and `kushner models`.
std::vector<std::string> model_names();

/// `kushner models`: names, descriptions, parameters with defaults and meanings.
nlohmann::json describe_models();

/// `model` with `assignments` ("key", "value") applied and checked: InputError for an unknown key, a malformed value
/// or an invalid configuration. Compiled once for every model of the lists, in registry.cpp, not in every file that
/// calls with_model or with_run_model: the parsing and the checks (Eigen's eigensolvers for every covariance).
template <class Model>
Model configured_model(Model model, const std::vector<std::pair<std::string, std::string>>& assignments) {
  apply_parameters(model, assignments);
  validate_model(model);
  return model;
}
#define KUSHNER_CONFIGURED_MODEL(Type) \
  extern template Type configured_model<Type>(Type, const std::vector<std::pair<std::string, std::string>>&);
KUSHNER_CONTINUOUS_MODELS(KUSHNER_CONFIGURED_MODEL)
KUSHNER_DISCRETE_MODELS(KUSHNER_CONFIGURED_MODEL)
KUSHNER_FILE_MODELS(KUSHNER_CONFIGURED_MODEL)
#undef KUSHNER_CONFIGURED_MODEL

/// Builds the model called `name`, applies `sets` ("key=value"), validates it, and calls f(model).
/// Throws InputError for an unknown model, an unknown key, a malformed value or an invalid configuration.
template <class F>
void with_model(const std::string& name, const std::vector<std::string>& sets, F&& f) {
  std::vector<std::pair<std::string, std::string>> assignments;
  int dim = 0;
  for (const auto& s : sets) {
    auto kv = split_assignment(s);
    if (kv.first == "dim") {
      const ParameterValue v = parse_parameter_value("dim", kv.second);
      KUSHNER_INPUT_REQUIRE(v.rows == 1 && v.cols == 1 && v.values[0] == static_cast<int>(v.values[0]),
                            "--set dim: expected an integer, got '" << kv.second << "'");
      dim = static_cast<int>(v.values[0]);
      continue;
    }
    assignments.push_back(std::move(kv));
  }
  bool name_known = false, called = false;
  std::string dims;
  detail::for_each_model_type([&](auto* tag) {
    using Model = std::remove_pointer_t<decltype(tag)>;
    if (called || name != Model::name) return;
    name_known = true;
    if constexpr (dimension_choice<Model>::selectable) {
      dims += (dims.empty() ? "" : ", ") + std::to_string(Model::state_dim);
      if ((dim == 0 ? dimension_choice<Model>::default_dim : dim) != Model::state_dim) return;
    } else {
      KUSHNER_INPUT_REQUIRE(dim == 0, "--set dim: model '" << name << "' has a fixed dimension " << Model::state_dim);
    }
    const Model model = configured_model(Model(), assignments);
    called = true;
    f(model);
  });
  if (called) return;
  if (name_known)
    throw InputError("--set dim: model '" + name + "' supports dim " + dims + " (got " + std::to_string(dim) + ")");
  std::string known;
  for (const auto& n : model_names()) known += (known.empty() ? "" : ", ") + n;
  throw InputError("--model: unknown model '" + name + "' (known: " + known + ")");
}

}  // namespace kushner
