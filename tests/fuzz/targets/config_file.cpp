// `--config FILE` for `kushner simulate`: an accepted file becomes `--key=value` arguments naming only the
// subcommand's own options, and those arguments go through the same command-line parse and checks as typed ones
// (CLI11 and validate_run_options may refuse them, never crash on them).
#include "drivers/config_file.hpp"
#include "core/errors.hpp"
#include "drivers/run_options.hpp"
#include "tests/fuzz/fuzz_check.hpp"
#include "tests/fuzz/fuzz_targets.hpp"

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace kushner::fuzz {

int config_file(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  RunOptions options;
  CLI::App app("fuzz", "kushner");
  CLI::App* simulate = app.add_subcommand("simulate");
  add_run_options(*simulate, options);
  try {
    const std::vector<std::string> args = config_arguments(text, "fuzz.toml", *simulate);
    for (const std::string& arg : args) {
      FUZZ_CHECK(arg.rfind("--", 0) == 0, "an argument that is not --key=value");
      const std::string name = arg.substr(0, arg.find('='));
      FUZZ_CHECK(name != "--config", "a config file that names --config");
      FUZZ_CHECK(simulate->get_option_no_throw(name) != nullptr, "an argument that is no option of simulate");
    }
    std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 consumes a reversed vector
    reversed.push_back("simulate");
    app.parse(reversed);
    validate_run_options(options);
  } catch (const InputError&) {
  } catch (const CLI::ParseError&) {  // the command line's own refusal (main prints it as one line, exit 2)
  }
  return 0;
}

}  // namespace kushner::fuzz
