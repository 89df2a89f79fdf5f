#pragma once
// The file format of DIR/checkpoint.bin: a header, then the run's archived state (Archive).
//
//   u64 22, "sheardiff-checkpoint-9"   (the magic, as Archive writes a string; the digit is
//                                        the layout of the state that follows)
//   u64 payload length in bytes
//   u32 CRC-32 (zlib) of the payload
//   payload
//
// Version 2 files (no header: the Archive stream began with "sheardiff-checkpoint-2") are
// still read, unchecked, so that runs started by an older sheardiff can be resumed. Layouts 2
// and 3 hold the pressure cell's gap profiles inside its own section; from layout 4 they are
// the profiles observer's: a pressure-cell run of layout 2 or 3 is refused with that reason
// (CheckpointStore), a simple-shear one resumes. Layout 5 adds, for the channel alone, the
// heights its fluid layer's sparsity pattern was built from (ForceBalance::on_rebuild): a
// layout-4 channel checkpoint resumes, not bit-identically. Layout 6 accumulates the diffusion
// analysis (earlier layouts kept its frames: refused). Layout 7 keeps the pressure cell's window
// samples in bounded bins (BinnedSeries); layout 6 kept every frame's, which are binned on
// reading: a layout-6 pressure-cell checkpoint resumes. Layout 8 keeps, for each contact of
// spheres, the stiffness its last cap left across its stretch (TangentialSpring3::across); a
// layout-7 checkpoint resumes with 1 there, which only contact.sliding_stiffness = "sideways"
// reads, for the step after the resume. Layout 9 adds the lubrication part of the gap profiles'
// stresses: a layout-8 checkpoint resumes, and a window it had begun reports no lubrication part.
// 9 is the last layout one digit of the magic holds.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/core/archive.hpp"

namespace sheardiff {

// A checkpoint that fails its checks: exit 2, the file is left as it is.
struct CorruptCheckpoint : ConfigError {
  using ConfigError::ConfigError;
};

std::uint32_t crc32_of(const std::vector<char>& bytes);

// The whole file for this payload.
std::vector<char> checkpoint_file_bytes(const std::vector<char>& payload);

struct CheckpointPayload {
  std::vector<char> bytes;        // the archived state, after the magic
  bool checksummed = true;        // false: a version 2 file, read without a check
  int layout = Archive::kLayout;  // the state layout: 2 to 9 (the magic's digit)
};

// Reads and checks FILE: the magic, the length against the file size, the CRC. Throws
// CorruptCheckpoint naming the file and what is wrong, or IoError if it cannot be read.
CheckpointPayload read_checkpoint_file(const std::filesystem::path& file);

}  // namespace sheardiff
