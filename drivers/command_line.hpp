#pragma once
// The whole `kushner` command line (drivers/command_line.cpp): main() only calls it, so that the command line
// compiles inside the driver library, beside the commands, and main.cpp alone waits for the library.

namespace kushner {

/// Runs the command line's subcommand; returns the process's exit code (2 for bad input, 1 for an internal error,
/// 128 + the signal for an interrupted run).
int command_line_main(int argc, char** argv);

}  // namespace kushner
