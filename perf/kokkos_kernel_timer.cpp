// A minimal Kokkos Tools library: wall time per kernel name and per deep_copy direction, printed at exit, for
// finding where a run's time goes where no profiler is installed (the GPU machine has no Nsight Systems).
// Kokkos fences the device after every kernel while a tool is loaded (unless the tool asks it not to), so a kernel's
// begin-to-end time is its launch and execution; the time outside kernels and copies is host work.
//   g++ -O2 -shared -fPIC perf/kokkos_kernel_timer.cpp -o kernel_timer.so
//   KOKKOS_PROFILE_LIBRARY=./kernel_timer.so kushner filter ...      (report on stderr)
// Compiled with -DKERNEL_TIMER_ASYNC it asks Kokkos for no fences: a kernel's time is then its launch's, how long the
// host spent in the call, and a launch that waits for the device stands out (Kokkos' constant-memory launches, of
// functors over 512 bytes, wait for the kernel of the one before). It then leaves copies untimed: for a tool that
// times them Kokkos reads each device view's label from device memory, a copy that waits for the device.
// KERNEL_TIMER_TRACE=FIRST:COUNT also lists the events FIRST to FIRST + COUNT - 1 in the order they began, each with
// its begin and end in microseconds since the first listed one: what the host did between two launches.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

struct Event {
  std::string name;
  double begin_us, end_us;
};

struct Trace {
  long first = -1, count = 0;  // the events listed
  long seen = 0;               // events begun so far
  Clock::time_point origin;
  std::vector<Event> events;
};

Trace& trace() {
  static Trace t;
  return t;
}

struct Total {
  long calls = 0;
  double seconds = 0.0;
};

std::map<std::string, Total>& totals() {
  static std::map<std::string, Total> t;
  return t;
}
Clock::time_point& library_start() {
  static Clock::time_point s;
  return s;
}

struct Open {
  std::string name;
  Clock::time_point start;
  long traced;  // index in trace().events, or -1
};

std::vector<Open>& open_events() {
  static std::vector<Open> o;
  return o;
}

void begin(const std::string& name, std::uint64_t* id) {
  const Clock::time_point now = Clock::now();
  Trace& t = trace();
  long traced = -1;
  const long index = t.seen++;
  if (t.first >= 0 && index >= t.first && index < t.first + t.count) {
    if (t.events.empty()) t.origin = now;
    traced = static_cast<long>(t.events.size());
    t.events.push_back({name, std::chrono::duration<double, std::micro>(now - t.origin).count(), 0.0});
  }
  open_events().push_back({name, now, traced});
  if (id) *id = open_events().size() - 1;
}
void end() {
  if (open_events().empty()) return;
  const Open o = open_events().back();
  open_events().pop_back();
  const Clock::time_point now = Clock::now();
  Total& t = totals()[o.name];
  ++t.calls;
  t.seconds += std::chrono::duration<double>(now - o.start).count();
  if (o.traced >= 0)
    trace().events[o.traced].end_us = std::chrono::duration<double, std::micro>(now - trace().origin).count();
}

}  // namespace

struct SpaceHandle {
  char name[64];
};

struct ToolSettings {  // Kokkos_Tools_ToolSettings (impl/Kokkos_Profiling_C_Interface.h)
  bool requires_global_fencing;
  bool padding[255];
};

extern "C" {

void kokkosp_init_library(int, std::uint64_t, std::uint32_t, void*) {
  library_start() = Clock::now();
  if (const char* spec = std::getenv("KERNEL_TIMER_TRACE")) {
    char* rest = nullptr;
    trace().first = std::strtol(spec, &rest, 10);
    trace().count = *rest == ':' ? std::strtol(rest + 1, nullptr, 10) : 100;
  }
}

#ifdef KERNEL_TIMER_ASYNC
void kokkosp_request_tool_settings(const std::uint32_t, ToolSettings* settings) {
  settings->requires_global_fencing = false;
}
#endif

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
  if (!trace().events.empty()) std::fprintf(stderr, "%10s %10s %9s  %s\n", "begin us", "end us", "took us", "event");
  for (const Event& e : trace().events)
    std::fprintf(stderr, "%10.1f %10.1f %9.1f  %s\n", e.begin_us, e.end_us, e.end_us - e.begin_us, e.name.c_str());
}

void kokkosp_begin_parallel_for(const char* name, std::uint32_t, std::uint64_t* id) { begin(name, id); }
void kokkosp_end_parallel_for(std::uint64_t) { end(); }
void kokkosp_begin_parallel_reduce(const char* name, std::uint32_t, std::uint64_t* id) { begin(name, id); }
void kokkosp_end_parallel_reduce(std::uint64_t) { end(); }
void kokkosp_begin_parallel_scan(const char* name, std::uint32_t, std::uint64_t* id) { begin(name, id); }
void kokkosp_end_parallel_scan(std::uint64_t) { end(); }
#ifndef KERNEL_TIMER_ASYNC
void kokkosp_begin_deep_copy(SpaceHandle dst, const char*, const void*, SpaceHandle src, const char*, const void*,
                             std::uint64_t) {
  begin(std::string("deep_copy ") + src.name + " -> " + dst.name, nullptr);
}
void kokkosp_end_deep_copy() { end(); }
#endif
void kokkosp_begin_fence(const char*, std::uint32_t, std::uint64_t* id) { begin("fence", id); }
void kokkosp_end_fence(std::uint64_t) { end(); }

}  // extern "C"
