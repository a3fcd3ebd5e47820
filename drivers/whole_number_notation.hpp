#pragma once
// Counts in the notation researchers write them in: `--members 1e6`, or a config file's `members = 1e6` (a TOML
// float, which reaches the command line as "1000000.0"), read as 1000000.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdlib>
#include <string>

namespace kushner {

/// A CLI11 transform for the integer options (->transform(whole_number_notation())): digits (with a sign) are left
/// to CLI11's conversion, which also refuses what is out of the option's range; a value with a decimal point or an
/// exponent that is exactly a whole number of magnitude at most 2^53 becomes its digits (a larger one is refused as
/// out of range); anything else is refused as "--members: expected a whole number (got '1.5')".
inline CLI::Validator whole_number_notation() {
  return CLI::Validator(
      [](std::string& value) {
        const std::size_t first_digit = (!value.empty() && (value[0] == '-' || value[0] == '+')) ? 1 : 0;
        if (value.size() > first_digit && value.find_first_not_of("0123456789", first_digit) == std::string::npos)
          return std::string();
        char* end = nullptr;
        const double number = std::strtod(value.c_str(), &end);
        const bool whole = !value.empty() && value.find_first_not_of("0123456789+-.eE") == std::string::npos &&
                           end == value.c_str() + value.size() && number == std::floor(number);
        if (!whole) return "expected a whole number (got '" + value + "')";
        if (!(std::fabs(number) <= 0x1p53)) return "out of range (got '" + value + "')";
        value = std::to_string(static_cast<long long>(number));
        return std::string();
      },
      "");
}

}  // namespace kushner
