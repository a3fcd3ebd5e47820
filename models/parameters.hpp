#pragma once
// Host side of model parameters: `--set key=value` parsing and application, listing, and JSON records.
// A model exposes its parameters once, through `template <class V> void parameters(V&& v)` calling
// v(name, field, description) for double, Vec<N> and Mat<R, C> fields; every visitor below serves all models.
#include "core/errors.hpp"
#include "core/small_matrix.hpp"
#include "models/parameter_value.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace kushner {

/// Applies one key=value to the field named key; `found` tells whether the model has such a field.
class ParameterSetter {
 public:
  /// `flag`: the option the assignment came from, for messages ("--set", "--cost").
  ParameterSetter(std::string key, std::string text, std::string flag = "--set")
      : key_(std::move(key)), text_(std::move(text)), flag_(std::move(flag)) {}
  bool found() const { return found_; }

  void operator()(const char* name, double& field, const char*) {
    if (key_ != name) return;
    const ParameterValue v = parse(name);
    expect_shape(v, 1, 1);
    field = v.values[0];
  }
  template <int N>
  void operator()(const char* name, Vec<N>& field, const char*) {
    if (key_ != name) return;
    const ParameterValue v = parse(name);
    if (v.rows == N && v.cols == 1) {
      for (int i = 0; i < N; ++i) field[i] = v.values[i];
      return;
    }
    expect_shape(v, 1, N);
    for (int i = 0; i < N; ++i) field[i] = v.values[i];
  }
  template <int R, int C>
  void operator()(const char* name, Mat<R, C>& field, const char*) {
    if (key_ != name) return;
    ParameterValue v = parse(name);
    if (C == 1 && R > 1 && v.rows == 1 && v.cols == R) std::swap(v.rows, v.cols);  // a column given as "0,1"
    expect_shape(v, R, C);
    for (int i = 0; i < R; ++i)
      for (int j = 0; j < C; ++j) field(i, j) = v.values[i * C + j];
  }

 private:
  ParameterValue parse(const char* name) {
    found_ = true;
    return parse_parameter_value(name, text_);
  }
  void expect_shape(const ParameterValue& v, int rows, int cols) const {
    KUSHNER_INPUT_REQUIRE(v.rows == rows && v.cols == cols,
                          flag_ << " " << key_ << ": expected " << shape_name(rows, cols) << ", got "
                                << shape_name(v.rows, v.cols) << " '" << text_ << "'");
  }
  static std::string shape_name(int rows, int cols) {
    if (rows == 1 && cols == 1) return "a number";
    if (rows == 1) return "a vector of " + std::to_string(cols);
    return "a " + std::to_string(rows) + "x" + std::to_string(cols) + " matrix";
  }
  std::string key_, text_, flag_;
  bool found_ = false;
};

/// Collects (name, value as JSON, description) of every parameter.
class ParameterRecorder {
 public:
  void operator()(const char* name, double& field, const char* description) { add(name, field, description); }
  template <int N>
  void operator()(const char* name, Vec<N>& field, const char* description) {
    add(name, std::vector<double>(field.v, field.v + N), description);
  }
  template <int R, int C>
  void operator()(const char* name, Mat<R, C>& field, const char* description) {
    std::vector<std::vector<double>> rows(R, std::vector<double>(C));
    for (int i = 0; i < R; ++i)
      for (int j = 0; j < C; ++j) rows[i][j] = field(i, j);
    add(name, rows, description);
  }
  struct Entry {
    std::string name;
    nlohmann::json value;
    std::string description;
  };
  const std::vector<Entry>& entries() const { return entries_; }
  nlohmann::json values() const {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& e : entries_) j[e.name] = e.value;
    return j;
  }

 private:
  void add(const char* name, nlohmann::json value, const char* description) {
    entries_.push_back({name, std::move(value), description});
  }
  std::vector<Entry> entries_;
};

/// Applies every "key=value" of `assignments` to `model`; unknown keys are InputErrors naming the known ones.
template <class Model>
void apply_parameters(Model& model, const std::vector<std::pair<std::string, std::string>>& assignments) {
  for (const auto& [key, text] : assignments) {
    ParameterSetter setter(key, text);
    model.parameters(setter);
    if (!setter.found()) {
      ParameterRecorder known;
      model.parameters(known);
      std::string names;
      for (const auto& e : known.entries()) names += (names.empty() ? "" : ", ") + e.name;
      throw InputError("--set " + key + ": model '" + Model::name + "' has no parameter '" + key +
                       "' (known: " + names + ")");
    }
  }
}

template <class Model>
nlohmann::json parameter_values(Model model) {
  ParameterRecorder recorder;
  model.parameters(recorder);
  return recorder.values();
}

}  // namespace kushner
