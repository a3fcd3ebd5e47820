#pragma once
// What every output file records about the run that made it: command, seed, version, backend.
#include "engine/backend.hpp"
#include "engine/version.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace kushner {

struct RunContext {
  std::string command;  // the command line, as typed (quoted where needed)
  std::uint32_t seed = 0;
  std::string backend;                 // an available_backends() name
  std::vector<std::string> arguments;  // argv[1 ..]: what a checkpoint records for `kushner resume`
};

/// {"name", "kokkos", "threads" or "device"}
nlohmann::json backend_json(const BackendDescription& description);

/// {"command", "seed", "version", "git", "backend": describe_backend(...)}; needs Kokkos initialized.
nlohmann::json run_metadata(const RunContext& context);

/// Leading comment line of CSV files: version, seed and command. The backend is in summary.json only, so
/// that a CSV is byte-identical whichever backend computed it (the numbers are).
std::string csv_comment(const RunContext& context);

/// argv joined into one line, each argument quoted when the shell would need it.
std::string command_line(int argc, char** argv);

}  // namespace kushner
