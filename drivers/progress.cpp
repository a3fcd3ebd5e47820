#include "drivers/progress.hpp"

#include "core/collectives.hpp"
#include "engine/processes.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <vector>

namespace kushner {

Progress::Progress(std::string label, long total, bool enabled)
    : label_(std::move(label)),
      total_(total > 0 ? total : 1),
      enabled_(enabled && (collective::ranks() > 1 || isatty(STDERR_FILENO))),
      ranks_(collective::ranks()),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() {
  // Every rank has the same --quiet, so either all ranks take part in this or none does.
  if (enabled_ && ranks_ > 1 && std::uncaught_exceptions() == 0) finish_progress();
  if (shown_) std::fprintf(stderr, "\n");
}

void Progress::update(long done) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_draw_ < std::chrono::milliseconds(100) && done < total_) return;
  last_draw_ = now;
  if (ranks_ > 1 && collective::rank() != 0) {
    send_progress(done);
    return;
  }
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (ranks_ == 1) {
    if (elapsed >= 1.0) draw(static_cast<double>(done) / total_, -1.0, elapsed);
    return;
  }
  const std::vector<long> latest = latest_progress(done);
  long sum = 0, slowest = total_;
  for (long d : latest) sum += d, slowest = std::min(slowest, d);
  if (elapsed >= 1.0)
    draw(static_cast<double>(sum) / (static_cast<double>(total_) * ranks_), static_cast<double>(slowest) / total_,
         elapsed);
}

void Progress::draw(double fraction, double slowest, double elapsed) {
  shown_ = true;
  constexpr int width = 40;
  const int filled = static_cast<int>(fraction * width);
  const double remaining = fraction > 0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  std::fprintf(stderr, "\r%s [%.*s%*s] %3.0f%%  %.0f s left ", label_.c_str(), filled,
               "########################################", width - filled, "", 100.0 * fraction, remaining);
  if (slowest >= 0.0) std::fprintf(stderr, "(%d ranks, slowest %.0f%%) ", ranks_, 100.0 * slowest);
  std::fflush(stderr);
}

}  // namespace kushner
