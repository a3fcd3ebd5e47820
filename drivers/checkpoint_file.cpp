#include "drivers/checkpoint_file.hpp"

#include "core/errors.hpp"
#include "engine/version.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <system_error>

namespace kushner {

namespace {

constexpr const char* format_line = "kushner checkpoint 1";

/// FNV-1a, 64 bits, over the arguments (each ended by a zero byte) and the state: a torn or edited file does
/// not pass for a checkpoint.
std::string checksum(const std::vector<std::string>& arguments, const std::string& state) {
  std::uint64_t h = 14695981039346656037ull;
  const auto add = [&h](const char* data, std::size_t size) {
    for (std::size_t i = 0; i < size; ++i) h = (h ^ static_cast<unsigned char>(data[i])) * 1099511628211ull;
  };
  for (const auto& a : arguments) add(a.c_str(), a.size() + 1);
  add(state.data(), state.size());
  std::ostringstream hex;
  hex << std::hex << h;
  return hex.str();
}

}  // namespace

std::string checkpoint_file_bytes(const Checkpoint& c) {
  const nlohmann::json header = {{"version", c.version},
                                 {"working_directory", c.working_directory},
                                 {"arguments", c.arguments},
                                 {"step", c.step},
                                 {"steps", c.steps},
                                 {"state_bytes", c.state.size()},
                                 {"checksum", checksum(c.arguments, c.state)}};
  return std::string(format_line) + "\n" + header.dump() + "\n" + c.state;
}

void write_checkpoint(const OutputDirectory& out, const Checkpoint& checkpoint) {
  out.write(checkpoint_file_name, checkpoint_file_bytes(checkpoint));
}

bool has_checkpoint(const std::filesystem::path& dir) {
  std::error_code ec;
  return std::filesystem::exists(dir / checkpoint_file_name, ec);
}

void remove_checkpoint(const OutputDirectory& out) {
  if (!out.writes()) return;
  std::error_code ignored;
  std::filesystem::remove(out.path() / checkpoint_file_name, ignored);
  // A kill in the middle of writing one leaves its .tmp.
  std::filesystem::remove(out.path() / (std::string(checkpoint_file_name) + ".tmp"), ignored);
}

Checkpoint read_checkpoint(const std::filesystem::path& dir) {
  const std::filesystem::path path = dir / checkpoint_file_name;
  const std::string where = "checkpoint '" + path.string() + "'";
  std::ifstream in(path, std::ios::binary);
  KUSHNER_INPUT_REQUIRE(in.good(), "resume: no checkpoint in '"
                                       << dir.string() << "' (a run writes one with --checkpoint-every SECONDS, or "
                                       << "when stopped by SIGINT or SIGTERM while it does)");
  std::string first, second;
  std::getline(in, first);
  KUSHNER_INPUT_REQUIRE(in.good() && first == format_line,
                        where << ": not a kushner checkpoint (first line '" << first.substr(0, 40) << "')");
  std::getline(in, second);
  nlohmann::json header;
  try {
    header = nlohmann::json::parse(second);
  } catch (const nlohmann::json::exception&) {
    KUSHNER_INPUT_REQUIRE(false, where << ": corrupt header");
  }
  Checkpoint c;
  std::size_t state_bytes = 0;
  std::string sum;
  try {
    c.version = header.at("version").get<std::string>();
    c.working_directory = header.at("working_directory").get<std::string>();
    c.arguments = header.at("arguments").get<std::vector<std::string>>();
    c.step = header.at("step").get<long>();
    c.steps = header.at("steps").get<long>();
    state_bytes = header.at("state_bytes").get<std::size_t>();
    sum = header.at("checksum").get<std::string>();
  } catch (const nlohmann::json::exception&) {
    KUSHNER_INPUT_REQUIRE(false, where << ": corrupt header");
  }
  KUSHNER_INPUT_REQUIRE(c.version == version_string(), where << ": written by " << c.version << "; this is "
                                                             << version_string()
                                                             << ": continue it with that build or start again");
  c.state.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  KUSHNER_INPUT_REQUIRE(c.state.size() == state_bytes,
                        where << ": truncated (" << c.state.size() << " of " << state_bytes << " bytes of state)");
  KUSHNER_INPUT_REQUIRE(checksum(c.arguments, c.state) == sum, where << ": corrupt (checksum mismatch)");
  KUSHNER_INPUT_REQUIRE(c.step >= 0 && c.step <= c.steps,
                        where << ": corrupt (step " << c.step << " of " << c.steps << ")");
  return c;
}

}  // namespace kushner
