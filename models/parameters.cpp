#include "models/parameter_value.hpp"

#include "core/errors.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>

namespace kushner {

namespace {

std::string strip(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t");
  if (begin == std::string::npos) return "";
  const auto end = s.find_last_not_of(" \t");
  return s.substr(begin, end - begin + 1);
}

double parse_number(const std::string& key, const std::string& token, const std::string& text) {
  const std::string t = strip(token);
  char* end = nullptr;
  const double value = std::strtod(t.c_str(), &end);
  KUSHNER_INPUT_REQUIRE(!t.empty() && end == t.c_str() + t.size(),
                        "--set " << key << ": '" << t << "' in '" << text << "' is not a number");
  KUSHNER_INPUT_REQUIRE(std::isfinite(value), "--set " << key << ": '" << t << "' is not finite");
  return value;
}

std::vector<std::string> split(const std::string& s, char separator) {
  std::vector<std::string> parts;
  std::string current;
  for (char c : s) {
    if (c == separator) {
      parts.push_back(current);
      current.clear();
    } else {
      current += c;
    }
  }
  parts.push_back(current);
  return parts;
}

}  // namespace

ParameterValue parse_parameter_value(const std::string& key, const std::string& text) {
  // Normalize the bracketed form "[[a, b], [c, d]]" to the row form "a, b; c, d".
  std::string s;
  for (char c : text)
    if (!std::isspace(static_cast<unsigned char>(c))) s += c;
  KUSHNER_INPUT_REQUIRE(!s.empty(), "--set " << key << ": empty value");
  if (s.rfind("[[", 0) == 0) {
    KUSHNER_INPUT_REQUIRE(s.size() >= 4 && s.compare(s.size() - 2, 2, "]]") == 0,
                          "--set " << key << ": unbalanced brackets in '" << text << "'");
    s = s.substr(2, s.size() - 4);
    std::string rows;
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s.compare(i, 3, "],[") == 0) {
        rows += ';';
        i += 2;
      } else {
        rows += s[i];
      }
    }
    s = rows;
  } else if (s.front() == '[') {
    KUSHNER_INPUT_REQUIRE(s.back() == ']', "--set " << key << ": unbalanced brackets in '" << text << "'");
    s = s.substr(1, s.size() - 2);
  }
  KUSHNER_INPUT_REQUIRE(s.find_first_of("[]") == std::string::npos,
                        "--set " << key << ": cannot read '" << text << "' (use 1,2;3,4 or [[1,2],[3,4]])");

  ParameterValue value;
  for (const std::string& row : split(s, ';')) {
    const auto cells = split(row, ',');
    if (value.rows == 0) value.cols = static_cast<int>(cells.size());
    KUSHNER_INPUT_REQUIRE(static_cast<int>(cells.size()) == value.cols,
                          "--set " << key << ": rows of different lengths in '" << text << "'");
    for (const auto& cell : cells) value.values.push_back(parse_number(key, cell, text));
    ++value.rows;
  }
  return value;
}

std::pair<std::string, std::string> split_assignment(const std::string& assignment) {
  const auto eq = assignment.find('=');
  const std::string key = eq == std::string::npos ? "" : strip(assignment.substr(0, eq));
  KUSHNER_INPUT_REQUIRE(!key.empty(), "--set: expected key=value, got '" << assignment << "'");
  return {key, assignment.substr(eq + 1)};
}

}  // namespace kushner
