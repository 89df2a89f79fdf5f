#pragma once
#include <cstddef>
#include <filesystem>
#include <string>

namespace sheardiff {

// write(2) of all SIZE bytes to FD: a signal or a pipe may cut one call short. False if a call
// fails (errno says why) or writes nothing.
bool write_all(int fd, const char* data, std::size_t size);

// Writes to FILE.tmp, flushes it to disk, then renames it over FILE: a reader (or a run killed
// mid-write) sees the old file or the new one, never a half-written one.
void write_file_atomically(const std::filesystem::path& file, const char* data, std::size_t size);
inline void write_file_atomically(const std::filesystem::path& file, const std::string& bytes) {
  write_file_atomically(file, bytes.data(), bytes.size());
}

}  // namespace sheardiff
