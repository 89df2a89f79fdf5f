#include "sheardiff/io/checkpoint_file.hpp"

#include <fmt/format.h>
#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "sheardiff/io/io_error.hpp"

namespace sheardiff {

namespace {

// The digit is the state layout (CheckpointPayload::layout): "sheardiff-checkpoint-N". Layout 2
// had no header; 3 to Archive::kLayout share it.
static_assert(Archive::kLayout >= 3 && Archive::kLayout <= 9, "one digit of layout in the magic");
std::string magic_of(int layout) {
  return fmt::format("sheardiff-checkpoint-{}", layout);
}
constexpr std::uint64_t kMagicLength = 22;
constexpr std::size_t kHeader = 8 + kMagicLength + 8 + 4;

template <class T>
T load(const char* p) {
  T x;
  std::memcpy(&x, p, sizeof(T));
  return x;
}
bool starts_with_magic(const std::vector<char>& b, const std::string& magic) {
  return b.size() >= 8 + kMagicLength && load<std::uint64_t>(b.data()) == kMagicLength &&
         std::memcmp(b.data() + 8, magic.data(), kMagicLength) == 0;
}

}  // namespace

std::uint32_t crc32_of(const std::vector<char>& bytes) {
  // zlib takes lengths as uInt: feed large payloads in pieces.
  uLong crc = crc32(0L, Z_NULL, 0);
  const auto* p = reinterpret_cast<const Bytef*>(bytes.data());
  for (std::size_t left = bytes.size(); left > 0;) {
    const auto n = static_cast<uInt>(std::min<std::size_t>(left, 1u << 30));
    crc = crc32(crc, p, n);
    p += n;
    left -= n;
  }
  return static_cast<std::uint32_t>(crc);
}

std::vector<char> checkpoint_file_bytes(const std::vector<char>& payload) {
  std::vector<char> out(kHeader + payload.size());
  char* p = out.data();
  const std::uint64_t magic_length = kMagicLength, length = payload.size();
  const std::uint32_t crc = crc32_of(payload);
  std::memcpy(p, &magic_length, 8);
  std::memcpy(p + 8, magic_of(Archive::kLayout).data(), kMagicLength);
  std::memcpy(p + 8 + kMagicLength, &length, 8);
  std::memcpy(p + 8 + kMagicLength + 8, &crc, 4);
  if (!payload.empty()) std::memcpy(p + kHeader, payload.data(), payload.size());
  return out;
}

CheckpointPayload read_checkpoint_file(const std::filesystem::path& file) {
  const auto corrupt = [&](const std::string& why) {
    return CorruptCheckpoint(fmt::format(
        "{} is corrupt: {}. It was neither resumed nor changed; keep a copy if you need it, "
        "then start the run again with --overwrite",
        file.string(), why));
  };
  // A stream opens a directory and fails only on reading it, with a message naming no file.
  std::error_code ec;
  if (std::filesystem::exists(file, ec) && !std::filesystem::is_regular_file(file, ec))
    throw corrupt("it is not a regular file (a directory?)");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw_io_error("read", file);
  std::vector<char> b;
  try {
    b.assign(std::istreambuf_iterator<char>(in), {});
  } catch (const std::exception&) {
    throw_io_error("read", file);
  }
  if (in.bad()) throw_io_error("read", file);
  CheckpointPayload out;
  if (starts_with_magic(b, magic_of(2))) {
    out.checksummed = false;
    out.layout = 2;
    out.bytes.assign(b.begin() + 8 + kMagicLength, b.end());
    return out;
  }
  out.layout = 0;
  for (int layout = 3; layout <= Archive::kLayout && out.layout == 0; ++layout)
    if (starts_with_magic(b, magic_of(layout))) out.layout = layout;
  if (out.layout == 0)
    throw corrupt(fmt::format("it does not begin with the magic \"{}\" ({} bytes)",
                              magic_of(Archive::kLayout), b.size()));
  if (b.size() < kHeader) throw corrupt(fmt::format("{} bytes, shorter than its header", b.size()));
  const auto length = load<std::uint64_t>(b.data() + 8 + kMagicLength);
  const auto stored = load<std::uint32_t>(b.data() + 8 + kMagicLength + 8);
  if (length != b.size() - kHeader)
    throw corrupt(fmt::format("its header gives {} bytes of state but the file holds {}", length,
                              b.size() - kHeader));
  out.bytes.assign(b.begin() + kHeader, b.end());
  const std::uint32_t computed = crc32_of(out.bytes);
  if (computed != stored)
    throw corrupt(fmt::format("CRC-32 {:08x} of its state differs from the {:08x} stored with it",
                              computed, stored));
  return out;
}

}  // namespace sheardiff
