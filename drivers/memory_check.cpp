#include "drivers/memory_check.hpp"

#include "core/collectives.hpp"
#include "core/errors.hpp"
#include "engine/backend_session.hpp"
#include "engine/processes.hpp"

#include <cstdio>
#include <optional>

namespace kushner {

std::string format_bytes(double bytes) {
  static const char* const units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  int unit = 0;
  while (bytes >= 1024.0 && unit < 6) bytes /= 1024.0, ++unit;
  char text[32];
  std::snprintf(text, sizeof text, unit == 0 ? "%.0f %s" : "%.3g %s", bytes, units[unit]);
  return text;
}

namespace {

/// What the ranks that share this process' memory need of a run needing `bytes` in all. Over MPI ranks a rank
/// holds about 1/ranks of the members (shares differ by one 256-member block at most), and the ranks that share
/// its memory (the node's host memory, or its GPU) need theirs as well.
double bytes_here(double bytes, const std::string& backend) {
  const int ranks = collective::ranks();
  return ranks > 1 ? bytes * ranks_sharing_memory(backend) / ranks : bytes;
}

}  // namespace

bool memory_fits(double bytes, const std::string& backend) {
  const std::optional<double> available = available_memory_bytes(backend);
  return !available || bytes_here(bytes, backend) <= *available;
}

void require_memory_fits(double bytes, const std::string& sizes, const std::string& breakdown,
                         const std::string& backend) {
  const std::optional<double> available = available_memory_bytes(backend);
  const int ranks = collective::ranks();
  const double here = bytes_here(bytes, backend);
  KUSHNER_INPUT_REQUIRE(!available || here <= *available,
                        sizes << ": the run needs " << format_bytes(here) << " (" << breakdown
                              << (ranks > 1 ? ", for the ranks that share this memory" : "") << "), but " << backend
                              << " has " << format_bytes(*available) << " available");
}

}  // namespace kushner
