#pragma once
// Where a run writes. Opened only after all input is validated; every file goes through `name.tmp` and a
// rename, so a failed or interrupted run never truncates results a previous run wrote.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace kushner {

class OutputDirectory {
 public:
  /// Creates `path` (and parents) if needed and checks that files can be created in it; InputError naming
  /// `option` (e.g. "--out") otherwise. In a run over MPI ranks only rank 0 does, and writes; on the other
  /// ranks the writes below do nothing (every rank computes the same contents).
  OutputDirectory(const std::filesystem::path& path, const std::string& option);

  /// Whether this process writes (rank 0, or the only process).
  bool writes() const { return writes_; }

  /// Writes `content` to path/name atomically (write name.tmp, then rename). InputError naming the option and
  /// the reason (disk full, ...) when it cannot, with name.tmp removed and path/name as it was.
  void write(const std::string& name, const std::string& content) const;

  /// Writes every (name, content) as name.tmp first and renames them only once all are written: a write that
  /// fails (disk full) removes this call's .tmp files and leaves the directory as it was, never a mix of this
  /// run's files and an earlier run's.
  void write_all(const std::vector<std::pair<std::string, std::string>>& files) const;

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::string option_;
  bool writes_ = true;
};

}  // namespace kushner
