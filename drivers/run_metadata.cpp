#include "drivers/run_metadata.hpp"

#include "core/collectives.hpp"
#include "engine/backend_session.hpp"
#include "engine/version.hpp"

#include <chrono>
#include <cstdio>

namespace kushner {

nlohmann::json backend_json(const BackendDescription& d) {
  nlohmann::json j = {{"name", d.name}, {"kokkos", d.kokkos}};
  if (!d.device.empty()) j["device"] = d.device;
  if (d.threads > 0) j["threads"] = d.threads;  // per rank
  if (collective::ranks() > 1) j["ranks"] = collective::ranks();
  return j;
}

nlohmann::json run_metadata(const RunContext& context) {
  return {{"command", context.command},
          {"seed", context.seed},
          {"version", version_number()},
          {"git", git_hash()},
          {"backend", backend_json(describe_backend(context.backend))}};
}

namespace {
std::chrono::steady_clock::time_point command_start() {
  static const std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  return start;
}
}  // namespace

void start_command_clock() { command_start(); }

double command_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - command_start()).count();
}

nlohmann::json timing_json(double step_loop_seconds, double member_steps, double particle_steps) {
  const auto rate = [&](double count) { return step_loop_seconds > 0.0 ? count / step_loop_seconds : 0.0; };
  nlohmann::json j = {{"step_loop_s", step_loop_seconds},
                      {"command_s", command_seconds()},
                      {"member_steps", member_steps},
                      {"member_steps_per_s", rate(member_steps)}};
  if (particle_steps > 0.0) {
    j["particle_steps"] = particle_steps;
    j["particle_steps_per_s"] = rate(particle_steps);
  }
  return j;
}

void print_timing(const nlohmann::json& t) {
  std::printf("wall time: step loop %.3g s (%.3g member-steps/s", t["step_loop_s"].get<double>(),
              t["member_steps_per_s"].get<double>());
  if (t.contains("particle_steps_per_s"))
    std::printf(", %.3g particle-steps/s", t["particle_steps_per_s"].get<double>());
  std::printf("), command %.3g s\n", t["command_s"].get<double>());
}

std::string csv_comment(const RunContext& context) {
  return "# " + version_string() + "; seed " + std::to_string(context.seed) + "; command: " + context.command + "\n";
}

std::string command_line(int argc, char** argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) {
    std::string arg = argv[i];
    if (i == 0) {
      const auto slash = arg.find_last_of('/');
      if (slash != std::string::npos) arg = arg.substr(slash + 1);
    }
    const bool plain =
        !arg.empty() &&
        arg.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_=./,:+@%") ==
            std::string::npos;
    if (!plain) {
      std::string quoted = "'";
      for (char c : arg) quoted += (c == '\'') ? std::string("'\\''") : std::string(1, c);
      arg = quoted + "'";
    }
    line += (i ? " " : "") + arg;
  }
  return line;
}

}  // namespace kushner
