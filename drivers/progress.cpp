#include "drivers/progress.hpp"

#include <unistd.h>
#include <cstdio>

namespace kushner {

Progress::Progress(std::string label, long total, bool enabled)
    : label_(std::move(label)),
      total_(total > 0 ? total : 1),
      enabled_(enabled && isatty(STDERR_FILENO)),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() {
  if (shown_) std::fprintf(stderr, "\n");
}

void Progress::update(long done) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (elapsed < 1.0 || (now - last_draw_ < std::chrono::milliseconds(100) && done < total_)) return;
  last_draw_ = now;
  shown_ = true;
  const double fraction = static_cast<double>(done) / total_;
  constexpr int width = 40;
  const int filled = static_cast<int>(fraction * width);
  const double remaining = fraction > 0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  std::fprintf(stderr, "\r%s [%.*s%*s] %3.0f%%  %.0f s left ", label_.c_str(), filled,
               "########################################", width - filled, "", 100.0 * fraction, remaining);
  std::fflush(stderr);
}

}  // namespace kushner
