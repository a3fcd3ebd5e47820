#include "drivers/output_directory.hpp"

#include "core/errors.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

namespace kushner {

OutputDirectory::OutputDirectory(const std::filesystem::path& path, const std::string& option) : path_(path) {
  KUSHNER_INPUT_REQUIRE(!path.empty(), option << ": empty path");
  std::error_code ec;
  if (std::filesystem::exists(path, ec)) {
    KUSHNER_INPUT_REQUIRE(std::filesystem::is_directory(path, ec),
                          option << ": '" << path.string() << "' exists and is not a directory");
  } else {
    std::filesystem::create_directories(path, ec);
    KUSHNER_INPUT_REQUIRE(!ec, option << ": cannot create directory '" << path.string() << "': " << ec.message());
  }
  // Probe: permissions alone do not tell (root, read-only mounts), creating a file does.
  const auto probe = path / ".kushner-write-test.tmp";
  {
    std::ofstream out(probe);
    KUSHNER_INPUT_REQUIRE(out.good(),
                          option << ": directory '" << path.string() << "' is not writable: " << std::strerror(errno));
  }
  std::filesystem::remove(probe, ec);
}

void OutputDirectory::write(const std::string& name, const std::string& content) const {
  const auto final_path = path_ / name;
  const auto tmp_path = path_ / (name + ".tmp");
  {
    std::ofstream out(tmp_path, std::ios::binary);
    out << content;
    out.close();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(tmp_path, ec);
      throw std::runtime_error("cannot write '" + tmp_path.string() + "': " + std::strerror(errno));
    }
  }
  std::filesystem::rename(tmp_path, final_path);
}

}  // namespace kushner
