#pragma once
// CLI11's App by name only, for the headers that declare functions taking one. CLI11 is header-only and its
// classes define their virtual functions in the class, so every translation unit that includes <CLI/CLI.hpp>
// compiles that code again (drivers/commands.hpp alone: 10.4 -> 6.0 s at -O3 here); only the sources that build
// the command line include it.
namespace CLI {
class App;
}
