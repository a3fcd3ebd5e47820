#pragma once
// The checkpoint file of an unfinished `kushner filter` or `compare` run, in its output directory: a first
// line naming the format, a JSON line (version, working directory, arguments, step, the state's size and
// checksum), then the state's bytes (engine/state_archive.hpp). Written atomically like every output file;
// removed when the run has written its results. `kushner resume DIR` reads it.
#include "drivers/output_directory.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace kushner {

inline constexpr const char* checkpoint_file_name = "checkpoint.kushner";

struct Checkpoint {
  std::string version;                 // version_string() of the build that wrote it
  std::string working_directory;       // where the run was started: relative paths in its arguments
  std::vector<std::string> arguments;  // argv[1 ..] of the run
  long step = 0, steps = 0;            // the state is the one after `step` of `steps` steps
  std::string state;
};

/// The file's bytes.
std::string checkpoint_file_bytes(const Checkpoint& checkpoint);

/// Writes out/checkpoint.kushner atomically (InputError as for any output file, e.g. disk full).
void write_checkpoint(const OutputDirectory& out, const Checkpoint& checkpoint);

/// Whether `dir` holds a checkpoint file.
bool has_checkpoint(const std::filesystem::path& dir);

/// Removes out/checkpoint.kushner and a .tmp a killed write left, if there (rank 0 only).
void remove_checkpoint(const OutputDirectory& out);

/// Reads dir/checkpoint.kushner. InputError (one line) when there is none, or it is truncated, corrupt (its
/// checksum), of another format, or written by another version of kushner.
Checkpoint read_checkpoint(const std::filesystem::path& dir);

}  // namespace kushner
