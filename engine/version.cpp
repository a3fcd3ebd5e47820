#include "engine/version.hpp"

#include "kushner_version.hpp"

namespace kushner {

std::string version_number() { return KUSHNER_VERSION_STRING; }
std::string git_hash() { return KUSHNER_GIT_HASH; }
std::string version_string() { return "kushner " + version_number() + " (git " + git_hash() + ")"; }

}  // namespace kushner
