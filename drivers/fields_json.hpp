#pragma once
// Fields (core/fields.hpp) written into JSON objects: a dotted key nests ("iterations.mean").
#include "core/fields.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <variant>

namespace kushner {

/// Adds every field to `object`.
inline void add_fields(nlohmann::json& object, const Fields& fields) {
  for (const Field& f : fields) {
    nlohmann::json* at = &object;
    std::string key = f.key;
    for (std::size_t dot = key.find('.'); dot != std::string::npos; dot = key.find('.')) {
      at = &(*at)[key.substr(0, dot)];
      key = key.substr(dot + 1);
    }
    std::visit([&](const auto& v) { (*at)[key] = v; }, f.value);
  }
}

/// The fields as a JSON object.
inline nlohmann::json fields_json(const Fields& fields) {
  nlohmann::json object = nlohmann::json::object();
  add_fields(object, fields);
  return object;
}

}  // namespace kushner
