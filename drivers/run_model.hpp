#pragma once
// The model of a run, from the command line: `--model-file FILE` (a polynomial model read from a file) or the
// built-in `--model NAME` with its `--set` assignments; and what summary.json records about it.
#include "drivers/model_file.hpp"
#include "models/registry.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace kushner {

/// The model of a run: `--model-file FILE` (a polynomial model, drivers/model_file.hpp) when given, else the
/// built-in `--model NAME`; calls f(model) as with_model does.
template <class F>
void with_run_model(const std::string& name, const std::string& model_file, const std::vector<std::string>& sets,
                    F&& f) {
  if (model_file.empty())
    with_model(name, sets, f);
  else
    with_model_file(model_file, sets, f);
}

/// summary.json's "model" entry: name, state_dim and parameters; for a polynomial model from a file also the
/// file and every coefficient as it runs (polynomial_model_json).
template <class Model>
nlohmann::json model_summary(const Model& model) {
  nlohmann::json j = {{"name", Model::name}, {"state_dim", Model::state_dim}, {"parameters", parameter_values(model)}};
  if constexpr (is_polynomial_model<Model>::value) {
    nlohmann::json polynomial = polynomial_model_json(model);
    for (const char* key : {"file", "label", "description"})
      if (polynomial.contains(key)) {
        j[key] = polynomial[key];
        polynomial.erase(key);
      }
    j["polynomial"] = polynomial;
  }
  return j;
}

}  // namespace kushner
