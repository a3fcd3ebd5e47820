#pragma once
// The fuzz targets' own checks: a property of a parser's result that must hold for every input it accepts. A
// failed one aborts, which libFuzzer reports as a crash (and saves the input), and which fails the replay test.
#include <cstdio>
#include <cstdlib>

#define FUZZ_CHECK(condition, what)                                                                        \
  do {                                                                                                     \
    if (!(condition)) {                                                                                    \
      std::fprintf(stderr, "fuzz check failed at %s:%d: %s (%s)\n", __FILE__, __LINE__, #condition, what); \
      std::abort();                                                                                        \
    }                                                                                                      \
  } while (false)
