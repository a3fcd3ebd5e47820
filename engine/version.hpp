#pragma once
// The version and commit this binary was built from (recorded in every output file and benchmark).
#include <string>

namespace kushner {

/// "0.1.0"
std::string version_number();
/// The commit, from `git describe` at build time ("unknown" outside a git checkout).
std::string git_hash();
/// "kushner 0.1.0 (git <hash>)"
std::string version_string();

}  // namespace kushner
