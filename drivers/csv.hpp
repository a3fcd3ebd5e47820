#pragma once
#include <cstdio>
#include <string>

namespace kushner {

/// Shortest round-trip form of a double (%.17g), so that CSV files hold exactly the numbers computed.
inline std::string format_number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

}  // namespace kushner
