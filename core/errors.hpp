#pragma once
// Host-side errors. Kernels never throw: they record a per-member Status instead (core/status.hpp).
#include <sstream>
#include <stdexcept>
#include <string>

namespace kushner {

/// Bad user input (unknown model, negative step, malformed file, ...): the CLI prints the message as one
/// line and exits with code 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace kushner

/// Broken invariant inside kushner (a bug, not bad input): std::logic_error with file and line.
#define KUSHNER_REQUIRE(condition, message)                                                           \
  do {                                                                                                \
    if (!(condition)) {                                                                               \
      std::ostringstream kushner_require_stream;                                                      \
      kushner_require_stream << __FILE__ << ":" << __LINE__ << ": " << #condition << ": " << message; \
      throw std::logic_error(kushner_require_stream.str());                                           \
    }                                                                                                 \
  } while (false)

/// Bad user input: throws kushner::InputError with the message.
#define KUSHNER_INPUT_REQUIRE(condition, message)              \
  do {                                                         \
    if (!(condition)) {                                        \
      std::ostringstream kushner_input_stream;                 \
      kushner_input_stream << message;                         \
      throw ::kushner::InputError(kushner_input_stream.str()); \
    }                                                          \
  } while (false)
