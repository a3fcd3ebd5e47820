// The fuzz targets in the normal build (ctest `fuzz_replay`): every file of the seed corpus and of the saved
// crashes (tests/fuzz/corpus/<target>/, tests/fuzz/regressions/<target>/) goes through its target, so that an
// input that once broke a parser keeps being tried by every build, sanitizer or not. A target that breaks a
// promise aborts (fuzz_check.hpp) and an unexpected exception escapes: either fails the test.
#include "tests/fuzz/fuzz_targets.hpp"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: fuzz_replay DIR... (each DIR holds one folder per target)\n";
    return 2;
  }
  int total = 0;
  for (int a = 1; a < argc; ++a) {
    for (const auto& target : kushner::fuzz::targets) {
      const std::filesystem::path folder = std::filesystem::path(argv[a]) / target.name;
      if (!std::filesystem::is_directory(folder)) continue;
      std::vector<std::filesystem::path> files;
      for (const auto& entry : std::filesystem::directory_iterator(folder))
        if (entry.is_regular_file()) files.push_back(entry.path());
      for (const auto& file : files) {
        std::ifstream in(file, std::ios::binary);
        const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        std::cerr << target.name << ": " << file.filename().string() << "\n";
        target.run(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
        ++total;
      }
    }
  }
  std::cout << "fuzz_replay: " << total << " inputs, none broke a parser\n";
  return total > 0 ? 0 : 1;  // no input at all: the folders were not found
}
