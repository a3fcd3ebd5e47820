#include "drivers/run_metadata.hpp"

#include "drivers/backend.hpp"
#include "kushner_version.hpp"

namespace kushner {

std::string version_string() { return std::string("kushner ") + KUSHNER_VERSION_STRING + " (git " + KUSHNER_GIT_HASH + ")"; }

nlohmann::json run_metadata(const RunContext& context) {
  return {{"command", context.command},
          {"seed", context.seed},
          {"version", KUSHNER_VERSION_STRING},
          {"git", KUSHNER_GIT_HASH},
          {"backend", describe_backend(context.backend)}};
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
    const bool plain = !arg.empty() && arg.find_first_not_of(
        "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_=./,:+@%") == std::string::npos;
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
