#pragma once
// The fuzz targets: one per parser of user (or data-file) text. Each takes any bytes, returns 0, and aborts
// only when a parser breaks a promise (fuzz_check.hpp); refusing the input with an InputError is a pass.
// One binary serves them all (KUSHNER_FUZZ_TARGET selects one), so that CI compiles the parsers once.
#include <cstddef>
#include <cstdint>

namespace kushner::fuzz {

using Target = int (*)(const std::uint8_t* data, std::size_t size);

struct NamedTarget {
  const char* name;  // also the folder of its seed corpus, tests/fuzz/corpus/<name>/
  Target run;
};

int config_file(const std::uint8_t* data, std::size_t size);   // --config TOML/INI
int model_file(const std::uint8_t* data, std::size_t size);    // --model-file
int set_value(const std::uint8_t* data, std::size_t size);     // --set key=value
int name_lists(const std::uint8_t* data, std::size_t size);    // --filters, --controllers
int paper_values(const std::uint8_t* data, std::size_t size);  // reproduce's paper-value tables

inline constexpr NamedTarget targets[] = {{"config_file", config_file},
                                          {"model_file", model_file},
                                          {"set_value", set_value},
                                          {"name_lists", name_lists},
                                          {"paper_values", paper_values}};

/// The target called `name`, or nullptr.
inline const NamedTarget* find_target(const char* name) {
  for (const NamedTarget& t : targets) {
    const char* a = t.name;
    const char* b = name;
    while (*a != '\0' && *a == *b) ++a, ++b;
    if (*a == '\0' && *b == '\0') return &t;
  }
  return nullptr;
}

}  // namespace kushner::fuzz
