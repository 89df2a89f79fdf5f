#pragma once
// Errors of the file system (a full disk, a missing or unwritable path): `sheardiff` exits 1 on
// them. The message names the file and the operating system's reason.
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace sheardiff {

struct IoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "cannot <action> <file>: <strerror(err)>"
[[noreturn]] inline void throw_io_error(const std::string& action,
                                        const std::filesystem::path& file, int err = errno) {
  throw IoError("cannot " + action + " " + file.string() + ": " + std::strerror(err));
}

}  // namespace sheardiff
