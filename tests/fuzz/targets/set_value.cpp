// `--set key=value` (and `--cost`): a value the parser accepts is a finite rows x cols block that prints back to
// itself, in the row form and in the bracketed form.
#include "core/errors.hpp"
#include "models/parameter_value.hpp"
#include "tests/fuzz/fuzz_check.hpp"
#include "tests/fuzz/fuzz_targets.hpp"

#include <cmath>
#include <cstdio>
#include <string>

namespace kushner::fuzz {

namespace {

std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

/// `v` written back: "a,b;c,d", or with brackets "[[a,b],[c,d]]".
std::string written(const ParameterValue& v, bool brackets) {
  std::string s = brackets ? "[[" : "";
  for (int i = 0; i < v.rows; ++i) {
    if (i > 0) s += brackets ? "],[" : ";";
    for (int j = 0; j < v.cols; ++j) s += (j > 0 ? "," : "") + number(v.values[i * v.cols + j]);
  }
  return s + (brackets ? "]]" : "");
}

void check_round_trip(const ParameterValue& v, bool brackets) {
  const ParameterValue again = parse_parameter_value("key", written(v, brackets));
  FUZZ_CHECK(again.rows == v.rows && again.cols == v.cols, "a value written back has another shape");
  for (std::size_t k = 0; k < v.values.size(); ++k)
    FUZZ_CHECK(again.values[k] == v.values[k], "a value written back reads as another number");
}

}  // namespace

int set_value(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  try {
    if (text.find('=') != std::string::npos) {
      const auto [key, value] = split_assignment(text);
      FUZZ_CHECK(!key.empty(), "split_assignment accepted an empty key");
      FUZZ_CHECK(key.front() != ' ' && key.back() != ' ' && key.front() != '\t' && key.back() != '\t',
                 "a key keeps its blanks");
      text = value;
    }
    const ParameterValue v = parse_parameter_value("key", text);
    FUZZ_CHECK(v.rows >= 1 && v.cols >= 1, "an accepted value has no entries");
    FUZZ_CHECK(v.values.size() == static_cast<std::size_t>(v.rows) * v.cols, "shape and entries disagree");
    for (double x : v.values) FUZZ_CHECK(std::isfinite(x), "an accepted value is not finite");
    check_round_trip(v, false);
    check_round_trip(v, true);
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace kushner::fuzz
