#include "drivers/config_file.hpp"

#include "core/errors.hpp"

#include <CLI/CLI.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace kushner {

std::vector<std::string> config_arguments(const std::string& text, const std::string& path,
                                          const CLI::App& subcommand) {
  std::vector<CLI::ConfigItem> items;
  try {
    std::istringstream in(text);
    items = CLI::ConfigTOML().from_config(in);
  } catch (const CLI::Error& e) {
    throw InputError(path + ": " + e.what());
  }
  std::vector<std::string> args;
  for (const auto& item : items) {
    if (item.name == "++" || item.name == "--") continue;  // section open/close markers
    KUSHNER_INPUT_REQUIRE(
        item.parents.empty() || (item.parents.size() == 1 && item.parents[0] == subcommand.get_name()),
        path << ": section '" << item.fullname() << "' is not [" << subcommand.get_name() << "]");
    const CLI::Option* option = subcommand.get_option_no_throw("--" + item.name);
    KUSHNER_INPUT_REQUIRE(option != nullptr && item.name != "config",
                          path << ": unknown key '" << item.name << "' (keys are the long options of `kushner "
                               << subcommand.get_name() << " --help`)");
    if (item.inputs.size() == 1) {
      args.push_back("--" + item.name + "=" + item.inputs[0]);
    } else {
      for (const auto& value : item.inputs) args.push_back("--" + item.name + "=" + value);
    }
  }
  return args;
}

std::vector<std::string> config_file_arguments(const std::string& path, const CLI::App& subcommand) {
  KUSHNER_INPUT_REQUIRE(std::filesystem::is_regular_file(path), "--config: cannot read '" << path << "'");
  std::ifstream file(path, std::ios::binary);
  std::ostringstream text;
  text << file.rdbuf();
  KUSHNER_INPUT_REQUIRE(file.good() || file.eof(), "--config: cannot read '" << path << "'");
  return config_arguments(text.str(), path, subcommand);
}

}  // namespace kushner
