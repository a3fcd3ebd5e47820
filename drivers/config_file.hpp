#pragma once
// `--config FILE` for a subcommand: CLI11 reads config files for the top-level app only, so the file's
// TOML/INI items become command-line arguments (`--key=value`), placed before the real command line so that
// options given there win. Keys are the long option names; a `[simulate]`-style section is optional.
#include "drivers/cli_app.hpp"

#include <string>
#include <vector>

namespace kushner {

/// Arguments equivalent to the config file text `text` (read from `path`, named in errors) for `subcommand`.
std::vector<std::string> config_arguments(const std::string& text, const std::string& path, const CLI::App& subcommand);

/// Arguments equivalent to the config file at `path` for `subcommand`. InputError (naming the file) when it
/// cannot be read, does not parse, or holds a key that is not an option of `subcommand`.
std::vector<std::string> config_file_arguments(const std::string& path, const CLI::App& subcommand);

}  // namespace kushner
