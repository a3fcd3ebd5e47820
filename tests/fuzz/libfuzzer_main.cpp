// The libFuzzer entry points: KUSHNER_FUZZ_TARGET names the target this process fuzzes (perf/fuzz.sh sets it).
#include "tests/fuzz/fuzz_targets.hpp"

#include <cstdio>
#include <cstdlib>

namespace {
kushner::fuzz::Target selected = nullptr;
}

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const char* name = std::getenv("KUSHNER_FUZZ_TARGET");
  const kushner::fuzz::NamedTarget* target = name ? kushner::fuzz::find_target(name) : nullptr;
  if (target == nullptr) {
    std::fprintf(stderr, "kushner_fuzz: set KUSHNER_FUZZ_TARGET to one of:");
    for (const auto& t : kushner::fuzz::targets) std::fprintf(stderr, " %s", t.name);
    std::fprintf(stderr, "\n");
    std::exit(2);
  }
  selected = target->run;
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { return selected(data, size); }
