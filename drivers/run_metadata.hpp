#pragma once
// What every output file records about the run that made it: command, seed, version, backend.
#include "engine/backend_session.hpp"
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

/// Starts the clock of the whole command (main calls it first; otherwise the first call to command_seconds).
void start_command_clock();
/// Wall seconds since start_command_clock.
double command_seconds();

/// What summary.json records of a run's speed under "timing": the wall time of the step loop (main pass,
/// fenced) and of the whole command so far, and the rates over the step loop. `member_steps`: members x
/// steps the loop ran (every rank's members); `particle_steps`: members x particles x steps where a particle
/// filter ran (0: none). Timing differs from run to run: tests that compare summaries byte for byte leave
/// "timing" out as they do "backend".
nlohmann::json timing_json(double step_loop_seconds, double member_steps, double particle_steps = 0.0);

/// One line on stdout from a timing_json: the step loop's wall time and rates, the command's wall time.
void print_timing(const nlohmann::json& timing);

/// Leading comment line of CSV files: version, seed and command. The backend is in summary.json only, so
/// that a CSV is byte-identical whichever backend computed it (the numbers are).
std::string csv_comment(const RunContext& context);

/// argv joined into one line, each argument quoted when the shell would need it.
std::string command_line(int argc, char** argv);

}  // namespace kushner
