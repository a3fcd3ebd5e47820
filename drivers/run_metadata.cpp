#include "drivers/run_metadata.hpp"

#include "core/collectives.hpp"
#include "engine/backend.hpp"
#include "engine/version.hpp"

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
