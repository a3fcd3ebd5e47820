#include "drivers/output_directory.hpp"

#include "core/collectives.hpp"
#include "core/errors.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

namespace kushner {

OutputDirectory::OutputDirectory(const std::filesystem::path& path, const std::string& option)
    : path_(path), option_(option), writes_(collective::rank() == 0) {
  KUSHNER_INPUT_REQUIRE(!path.empty(), option << ": empty path");
  if (!writes_) return;
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

void OutputDirectory::write(const std::string& name, const std::string& content) const { write_all({{name, content}}); }

void OutputDirectory::write_all(const std::vector<std::pair<std::string, std::string>>& files) const {
  if (!writes_) return;
  std::vector<std::filesystem::path> written;  // the .tmp files of this call
  auto remove_written = [&written] {
    std::error_code ignored;
    for (const auto& tmp : written) std::filesystem::remove(tmp, ignored);
  };
  for (const auto& [name, content] : files) {
    const auto tmp_path = path_ / (name + ".tmp");
    std::ofstream out(tmp_path, std::ios::binary);
    out << content;
    out.close();
    if (!out) {
      const int error = errno;  // ENOSPC from the write or the close: the reason to report
      written.push_back(tmp_path);
      remove_written();
      KUSHNER_INPUT_REQUIRE(false, option_ << ": cannot write '" << (path_ / name).string()
                                           << "': " << std::strerror(error) << " (files already there are unchanged)");
    }
    written.push_back(tmp_path);
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    std::error_code ec;
    std::filesystem::rename(written[i], path_ / files[i].first, ec);
    if (ec) {
      remove_written();
      KUSHNER_INPUT_REQUIRE(false, option_ << ": cannot rename '" << written[i].string() << "' to '" << files[i].first
                                           << "': " << ec.message());
    }
  }
}

}  // namespace kushner
