#include "engine/run_checkpointing.hpp"

#include <atomic>
#include <csignal>

namespace kushner {

namespace {
std::atomic<int> received{0};
// Lock-free, so safe in a signal handler.
void remember_signal(int signal) { received.store(signal); }
}  // namespace

void catch_stop_signals() {
  std::signal(SIGINT, remember_signal);
  std::signal(SIGTERM, remember_signal);
}

int stop_signal() { return received.load(); }

std::string signal_name(int signal) {
  if (signal == SIGINT) return "SIGINT";
  if (signal == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signal);
}

}  // namespace kushner
