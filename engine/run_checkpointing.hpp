#pragma once
// What a run needs to write checkpoints and to continue from one (`--checkpoint-every`, `kushner resume`):
// when to save, where the bytes go, the caller's own state, and the state to continue from. The engine saves
// between steps, so a checkpoint holds the state after step k; draws are keyed by (seed, stream, member,
// particle, step), so a run continued from it makes the same numbers as one never stopped.
#include <chrono>
#include <functional>
#include <stdexcept>
#include <string>

namespace kushner {

class StateArchive;  // engine/state_archive.hpp (Kokkos): the command line includes this header without Kokkos

struct RunCheckpointing {
  /// Save when this many seconds have passed since the start or the last save; < 0: only on SIGINT/SIGTERM.
  double every_seconds = -1.0;
  /// Writes a saved state (after `step` of `steps` steps). Empty: the run makes no checkpoints.
  std::function<void(const std::string& state, long step, long steps)> write;
  /// The caller's part of the state (saved first: e.g. the arguments the state must match, a recorder).
  std::function<void(StateArchive&)> visit_caller_state;
  /// A saved state to continue from (nullptr: start at step 0).
  const std::string* resume = nullptr;
  /// Appended to the message of an interrupted run (e.g. "continue with `kushner resume DIR`").
  std::string resume_hint;

  bool saves() const { return static_cast<bool>(write); }
};

/// A run stopped by SIGINT or SIGTERM after writing its checkpoint: the command line prints the message and
/// exits with 128 + signal.
class RunInterrupted : public std::runtime_error {
 public:
  RunInterrupted(const std::string& message, int signal) : std::runtime_error(message), signal_(signal) {}
  int signal() const { return signal_; }

 private:
  int signal_;
};

/// From now on SIGINT and SIGTERM only set a flag that stop_signal() returns (0: none yet), so that a run that
/// saves checkpoints can save one and stop cleanly.
void catch_stop_signals();
int stop_signal();
/// "SIGINT", "SIGTERM", or "signal N".
std::string signal_name(int signal);

/// When the next timed save is due.
class CheckpointClock {
 public:
  explicit CheckpointClock(double every_seconds) : every_(every_seconds), last_(std::chrono::steady_clock::now()) {}
  bool due() const {
    return every_ >= 0.0 && std::chrono::duration<double>(std::chrono::steady_clock::now() - last_).count() >= every_;
  }
  void restart() { last_ = std::chrono::steady_clock::now(); }

 private:
  double every_;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace kushner
