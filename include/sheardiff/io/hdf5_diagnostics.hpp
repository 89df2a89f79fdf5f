#pragma once
// HDF5's own error reporting. Its automatic print of the error stack to stderr is turned off
// (a full disk printed thousands of HDF5-DIAG lines over the one line that says what failed);
// a run sends the stacks to DIR/run.log instead, and the errors thrown on HDF5 failures carry
// the operating system's reason found in the stack. (HDF5's C API stays out of this header.)
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

namespace sheardiff {

// Once, first thing in a process: no automatic error stack printing, and no library shutdown
// at exit. After a write failed (a full disk) HDF5 cannot close the file, and its shutdown
// then loops ("infinite loop closing library") or crashes; the run has failed anyway and the
// operating system closes the file.
void quiet_hdf5_for_process();

// The operating system's reason recorded in the calling thread's HDF5 error stack (e.g. "No
// space left on device"), or "" if the stack names none. Valid right after the failed call.
std::string hdf5_os_reason();

// Whether FILE opens as an HDF5 file: a file whose writer died or hit a full disk before its
// close is truncated, and HDF5 refuses it.
bool hdf5_file_opens(const std::filesystem::path& file);

// While alive, every HDF5 error stack is printed to `log` (a file the caller owns), and counted
// with its operating system reason: a caller that gets a bare "cannot write" from code that
// ignores HDF5's return codes can still tell the user why.
class Hdf5ErrorLog {
 public:
  explicit Hdf5ErrorLog(std::FILE* log);
  ~Hdf5ErrorLog();
  Hdf5ErrorLog(const Hdf5ErrorLog&) = delete;
  Hdf5ErrorLog& operator=(const Hdf5ErrorLog&) = delete;

  long errors() const;
  // The operating system reason of the latest error that named one, or "".
  const std::string& last_os_reason() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace sheardiff
