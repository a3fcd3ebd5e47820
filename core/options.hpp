#pragma once
// Options a component declares once (name, default, range, help), and the values a run gives them. The command
// line, config files and `kushner filters` are generated from the declarations and check every value against
// them where it is read (drivers/filter_options.cpp); components read checked values by name.
#include "core/errors.hpp"
#include "core/fields.hpp"

#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace kushner {

struct OptionSpec {
  enum class Kind { integer, real, choice };
  std::string name;  // snake_case, e.g. "gh_nodes"; the command line spells it --gh-nodes
  Kind kind = Kind::integer;
  Value default_value;
  double min = -std::numeric_limits<double>::infinity();  // integer, real: accepted range, inclusive
  double max = std::numeric_limits<double>::infinity();
  bool positive = false;             // real: must be > 0
  std::vector<std::string> choices;  // choice: the accepted words
  std::string help;

  static OptionSpec integer(std::string name, long default_value, long min, long max, std::string help) {
    OptionSpec s{std::move(name), Kind::integer, default_value};
    s.min = static_cast<double>(min), s.max = static_cast<double>(max), s.help = std::move(help);
    return s;
  }
  static OptionSpec positive_real(std::string name, double default_value, std::string help) {
    OptionSpec s{std::move(name), Kind::real, default_value};
    s.positive = true, s.help = std::move(help);
    return s;
  }
  static OptionSpec choice(std::string name, std::string default_value, std::vector<std::string> choices,
                           std::string help) {
    OptionSpec s{std::move(name), Kind::choice, std::move(default_value)};
    s.choices = std::move(choices), s.help = std::move(help);
    return s;
  }
};

/// What is wrong with `value` for `spec` ("must be in 1 .. 40 (got 0)", "must be positive (got -1)"), or "".
inline std::string option_value_problem(const OptionSpec& spec, const Value& value) {
  std::ostringstream why;
  switch (spec.kind) {
    case OptionSpec::Kind::integer: {
      const long* v = std::get_if<long>(&value);
      if (!v) return "expected an integer";
      if (*v < spec.min || *v > spec.max)
        why << "must be in " << static_cast<long>(spec.min) << " .. " << static_cast<long>(spec.max) << " (got " << *v
            << ")";
      break;
    }
    case OptionSpec::Kind::real: {
      const double* v = std::get_if<double>(&value);
      if (!v) return "expected a number";
      if (spec.positive && !(*v > 0.0 && *v <= std::numeric_limits<double>::max()))
        why << "must be positive (got " << *v << ")";
      else if (!(*v >= spec.min && *v <= spec.max))
        why << "must be in [" << spec.min << ", " << spec.max << "] (got " << *v << ")";
      break;
    }
    case OptionSpec::Kind::choice: {
      const std::string* v = std::get_if<std::string>(&value);
      if (!v) return "expected a word";
      bool known = false;
      for (const auto& c : spec.choices) known = known || c == *v;
      if (!known) {
        why << "unknown value '" << *v << "' (known:";
        for (std::size_t i = 0; i < spec.choices.size(); ++i) why << (i ? ", " : " ") << spec.choices[i];
        why << ")";
      }
      break;
    }
  }
  return why.str();
}

/// The values of a run's options, by name. Components read only names they declared (std::logic_error
/// otherwise): a misspelt name is a bug, not input.
class OptionValues {
 public:
  void set(const std::string& name, Value value) { values_[name] = std::move(value); }
  bool has(const std::string& name) const { return values_.count(name) != 0; }
  long integer(const std::string& name) const { return get<long>(name); }
  double real(const std::string& name) const { return get<double>(name); }
  const std::string& word(const std::string& name) const { return get<std::string>(name); }

  /// Every declared default that `specs` has and this does not.
  OptionValues with_defaults(const std::vector<OptionSpec>& specs) const {
    OptionValues v = *this;
    for (const auto& s : specs)
      if (!v.has(s.name)) v.set(s.name, s.default_value);
    return v;
  }

 private:
  template <class T>
  const T& get(const std::string& name) const {
    const auto it = values_.find(name);
    KUSHNER_REQUIRE(it != values_.end(), "option '" << name << "' has no value");
    const T* v = std::get_if<T>(&it->second);
    KUSHNER_REQUIRE(v != nullptr, "option '" << name << "' holds another type");
    return *v;
  }
  std::map<std::string, Value> values_;
};

/// A value that is valid for its option but not for this run's model: which option, and why.
struct OptionProblem {
  std::string option, message;
};

}  // namespace kushner
