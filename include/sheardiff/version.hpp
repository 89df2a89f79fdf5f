#pragma once
// Which sheardiff this is: `sheardiff --version`, and the "version" and "git_hash" of every
// summary.json. git_hash() comes from the source tree when CMake configured the build
// (cmake/GitVersion.cmake).
#include <string>

namespace sheardiff {

// The release, "0.1.0" (CMakeLists.txt, project VERSION).
const char* version();
// `git rev-parse --short HEAD` of the source ("3f2c1ab"), "-dirty" appended if tracked files
// had changes, "unknown" if it was not built from a git checkout.
const char* git_hash();
// "sheardiff 0.1.0 (git 3f2c1ab)".
inline std::string version_line() {
  return std::string("sheardiff ") + version() + " (git " + git_hash() + ")";
}

}  // namespace sheardiff
