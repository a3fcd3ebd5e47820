#pragma once
// Counts in the notation researchers write them in: `--members 1e6`, or a config file's `members = 1e6` (a TOML
// float, which reaches the command line as "1000000.0"), read as 1000000.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdlib>
#include <string>

namespace kushner {

/// A CLI11 transform for the integer options (->transform(whole_number_notation())): a value with a decimal point
/// or an exponent that is exactly a whole number of magnitude at most 2^53 becomes its digits; any other value is
/// left as it is, for CLI11's integer conversion to take ("1000") or refuse ("1.5", "lots").
inline CLI::Validator whole_number_notation() {
  return CLI::Validator(
      [](std::string& value) {
        if (value.find_first_of(".eE") == std::string::npos ||
            value.find_first_not_of("0123456789+-.eE") != std::string::npos)
          return std::string();
        char* end = nullptr;
        const double number = std::strtod(value.c_str(), &end);
        if (end == value.c_str() + value.size() && std::fabs(number) <= 0x1p53 && number == std::floor(number))
          value = std::to_string(static_cast<long long>(number));
        return std::string();
      },
      "");
}

}  // namespace kushner
