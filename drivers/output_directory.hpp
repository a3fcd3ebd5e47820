#pragma once
// Where a run writes. Opened only after all input is validated; every file goes through `name.tmp` and a
// rename, so a failed or interrupted run never truncates results a previous run wrote.
#include <filesystem>
#include <string>

namespace kushner {

class OutputDirectory {
 public:
  /// Creates `path` (and parents) if needed and checks that files can be created in it; InputError naming
  /// `option` (e.g. "--out") otherwise.
  OutputDirectory(const std::filesystem::path& path, const std::string& option);

  /// Writes `content` to path/name atomically (write name.tmp, then rename).
  void write(const std::string& name, const std::string& content) const;

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace kushner
