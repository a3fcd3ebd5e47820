#pragma once
// `--set key=value` text as numbers, apart from the models (models/parameters.hpp applies them): it includes
// neither Kokkos nor JSON, so that the fuzz target of tests/fuzz/ builds it alone.
#include <string>
#include <utility>
#include <vector>

namespace kushner {

/// A parsed value: a scalar "0.5", a vector "1,2" or "[1, 2]", a matrix "1,0;0,1" or "[[1, 0], [0, 1]]".
struct ParameterValue {
  int rows = 0, cols = 0;
  std::vector<double> values;  // row-major
};

ParameterValue parse_parameter_value(const std::string& key, const std::string& text);

/// "key=value" -> (key, value); InputError when there is no '=' or an empty key.
std::pair<std::string, std::string> split_assignment(const std::string& assignment);

}  // namespace kushner
