#include "sheardiff/io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>

#include "sheardiff/io/io_error.hpp"

namespace sheardiff {

bool write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

void write_file_atomically(const std::filesystem::path& file, const char* data, std::size_t size) {
  const std::filesystem::path tmp = file.string() + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw_io_error("write", tmp);
  const bool ok = write_all(fd, data, size) && ::fsync(fd) == 0;
  const int err = errno;
  if (::close(fd) != 0 || !ok) {
    const int reason = ok ? errno : err;
    // A partial FILE.tmp would only puzzle whoever looks at the folder.
    ::unlink(tmp.c_str());
    throw_io_error("write", tmp, reason);
  }
  if (::rename(tmp.c_str(), file.c_str()) != 0) {
    const int err_rename = errno;
    ::unlink(tmp.c_str());
    throw_io_error("rename " + tmp.string() + " to", file, err_rename);
  }
  // The rename is durable only once the folder is on disk: a power cut must not bring back
  // the old file next to a newer one (a summary.json without its checkpoint removed, ...).
  const auto dir = file.parent_path().empty() ? std::filesystem::path(".") : file.parent_path();
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace sheardiff
