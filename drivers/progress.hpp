#pragma once
// A progress bar on stderr for long runs: shown only when stderr is a terminal, the run is not --quiet,
// and it has taken more than a second; redrawn at most ten times a second.
#include <chrono>
#include <string>

namespace kushner {

class Progress {
 public:
  Progress(std::string label, long total, bool enabled);
  ~Progress();
  void update(long done);

 private:
  std::string label_;
  long total_;
  bool enabled_, shown_ = false;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace kushner
