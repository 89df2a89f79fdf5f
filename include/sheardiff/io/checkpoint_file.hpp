#pragma once
// The file format of DIR/checkpoint.bin: a header, then the run's archived state (Archive).
//
//   u64 22, "sheardiff-checkpoint-3"   (the magic, as Archive writes a string)
//   u64 payload length in bytes
//   u32 CRC-32 (zlib) of the payload
//   payload
//
// Version 2 files (no header: the Archive stream began with "sheardiff-checkpoint-2") are
// still read, unchecked, so that runs started by an older sheardiff can be resumed.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "sheardiff/config.hpp"

namespace sheardiff {

// A checkpoint that fails its checks: exit 2, the file is left as it is.
struct CorruptCheckpoint : ConfigError {
  using ConfigError::ConfigError;
};

std::uint32_t crc32_of(const std::vector<char>& bytes);

// The whole file for this payload.
std::vector<char> checkpoint_file_bytes(const std::vector<char>& payload);

struct CheckpointPayload {
  std::vector<char> bytes;  // the archived state, after the magic
  bool checksummed = true;  // false: a version 2 file, read without a check
};

// Reads and checks FILE: the magic, the length against the file size, the CRC. Throws
// CorruptCheckpoint naming the file and what is wrong, or IoError if it cannot be read.
CheckpointPayload read_checkpoint_file(const std::filesystem::path& file);

}  // namespace sheardiff
