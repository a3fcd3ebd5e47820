// A minimal Kokkos Tools library: wall time per kernel name and per deep_copy direction, printed at exit, for
// finding where a run's time goes where no profiler is installed (the GPU machine has no Nsight Systems).
// With CUDA_LAUNCH_BLOCKING=1 every kernel ends before its launch returns, so its begin-to-end time is its
// execution time; the time outside kernels and copies is host work and waiting.
//   g++ -O2 -shared -fPIC perf/kokkos_kernel_timer.cpp -o kernel_timer.so
//   CUDA_LAUNCH_BLOCKING=1 KOKKOS_PROFILE_LIBRARY=./kernel_timer.so kushner filter ...      (report on stderr)
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

struct Total {
  long calls = 0;
  double seconds = 0.0;
};

std::map<std::string, Total>& totals() {
  static std::map<std::string, Total> t;
  return t;
}
std::vector<std::pair<std::string, Clock::time_point>>& open_regions() {
  static std::vector<std::pair<std::string, Clock::time_point>> o;
  return o;
}
Clock::time_point& library_start() {
  static Clock::time_point s;
  return s;
}

void begin(const std::string& name, std::uint64_t* id) {
  open_regions().emplace_back(name, Clock::now());
  if (id) *id = open_regions().size() - 1;
}
void end() {
  if (open_regions().empty()) return;
  const auto [name, start] = open_regions().back();
  open_regions().pop_back();
  Total& t = totals()[name];
  ++t.calls;
  t.seconds += std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

struct SpaceHandle {
  char name[64];
};

extern "C" {

void kokkosp_init_library(int, std::uint64_t, std::uint32_t, void*) { library_start() = Clock::now(); }

void kokkosp_finalize_library() {
  const double wall = std::chrono::duration<double>(Clock::now() - library_start()).count();
  double counted = 0.0;
  std::fprintf(stderr, "kernel timer: %.4f s between Kokkos' initialize and finalize\n", wall);
  std::fprintf(stderr, "%12s %8s %12s  %s\n", "seconds", "calls", "us per call", "kernel or copy");
  for (const auto& [name, t] : totals()) {
    counted += t.seconds;
    std::fprintf(stderr, "%12.4f %8ld %12.1f  %s\n", t.seconds, t.calls, 1e6 * t.seconds / t.calls, name.c_str());
  }
  std::fprintf(stderr, "%12.4f %8s %12s  %s\n", wall - counted, "", "", "(outside kernels and copies)");
}

void kokkosp_begin_parallel_for(const char* name, std::uint32_t, std::uint64_t* id) { begin(name, id); }
void kokkosp_end_parallel_for(std::uint64_t) { end(); }
void kokkosp_begin_parallel_reduce(const char* name, std::uint32_t, std::uint64_t* id) { begin(name, id); }
void kokkosp_end_parallel_reduce(std::uint64_t) { end(); }
void kokkosp_begin_parallel_scan(const char* name, std::uint32_t, std::uint64_t* id) { begin(name, id); }
void kokkosp_end_parallel_scan(std::uint64_t) { end(); }
void kokkosp_begin_deep_copy(SpaceHandle dst, const char*, const void*, SpaceHandle src, const char*, const void*,
                             std::uint64_t) {
  begin(std::string("deep_copy ") + src.name + " -> " + dst.name, nullptr);
}
void kokkosp_end_deep_copy() { end(); }
void kokkosp_begin_fence(const char*, std::uint32_t, std::uint64_t* id) { begin("fence", id); }
void kokkosp_end_fence(std::uint64_t) { end(); }

}  // extern "C"
