#include "sheardiff/io/atomic_file.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <stdexcept>

namespace sheardiff {

void write_file_atomically(const std::filesystem::path& file, const char* data, std::size_t size) {
  const auto tmp = file.string() + ".tmp";
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw std::runtime_error(fmt::format("cannot write {}", tmp));
  const bool ok = std::fwrite(data, 1, size, f) == size &&
                  std::fflush(f) == 0 && fsync(fileno(f)) == 0;
  if (std::fclose(f) != 0 || !ok) throw std::runtime_error(fmt::format("cannot write {}", tmp));
  std::filesystem::rename(tmp, file);
}

}  // namespace sheardiff
