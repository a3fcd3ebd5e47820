#pragma once
// Named values a component reports about a run (a filter's extra summary fields, an estimator's description),
// without knowing the output format: drivers write them as JSON objects. A dotted key nests
// ("iterations.mean" is the "mean" of the object "iterations").
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace kushner {

/// An integer, a real number or a word: what options take and what components report.
using Value = std::variant<long, double, std::string>;

struct Field {
  std::string key;
  Value value;
};
using Fields = std::vector<Field>;

/// The value of `key` in `fields` (nullptr when absent).
inline const Value* find_field(const Fields& fields, const std::string& key) {
  for (const Field& f : fields)
    if (f.key == key) return &f.value;
  return nullptr;
}

}  // namespace kushner
