#pragma once
// A progress bar on stderr for long runs: shown only when stderr is a terminal, the run is not --quiet,
// and it has taken more than a second; redrawn at most ten times a second. In a run over MPI ranks rank 0
// draws it for all ranks (the others send it their step counts): there stderr is mpirun's pipe, whatever
// mpirun's own stderr is, so the bar is drawn unless --quiet.
#include <chrono>
#include <string>

namespace kushner {

class Progress {
 public:
  Progress(std::string label, long total, bool enabled);
  /// Collective across ranks (unless an exception is unwinding it: the ranks are then being ended).
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  void update(long done);

 private:
  void draw(double fraction, double slowest, double elapsed);

  std::string label_;
  long total_;
  bool enabled_, shown_ = false;
  int ranks_;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace kushner
