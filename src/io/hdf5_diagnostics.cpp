#include "sheardiff/io/hdf5_diagnostics.hpp"

#include <hdf5.h>

#include <cstdlib>
#include <cstring>

namespace sheardiff {

void quiet_hdf5_for_process() {
  H5dont_atexit();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

namespace {

// HDF5's POSIX driver records "errno = 28, error message = '...'" in its message.
herr_t find_errno(unsigned, const H5E_error2_t* e, void* data) {
  auto* reason = static_cast<std::string*>(data);
  if (!reason->empty() || e->desc == nullptr) return 0;
  if (const char* at = std::strstr(e->desc, "errno = ")) {
    const int err = std::atoi(at + 8);
    if (err > 0) *reason = std::strerror(err);
  }
  return 0;
}

}  // namespace

std::string hdf5_os_reason() {
  std::string reason;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, find_errno, &reason);
  return reason;
}

bool hdf5_file_opens(const std::filesystem::path& file) {
  H5E_auto2_t func = nullptr;
  void* data = nullptr;
  H5Eget_auto2(H5E_DEFAULT, &func, &data);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f >= 0) H5Fclose(f);
  H5Eset_auto2(H5E_DEFAULT, func, data);
  return f >= 0;
}

struct Hdf5ErrorLog::State {
  std::FILE* log = nullptr;
  long errors = 0;
  std::string last_os_reason;
  H5E_auto2_t saved_func = nullptr;
  void* saved_data = nullptr;

  static herr_t on_error(hid_t stack, void* data) {
    auto* self = static_cast<State*>(data);
    ++self->errors;
    std::string reason;
    H5Ewalk2(stack, H5E_WALK_DOWNWARD, find_errno, &reason);
    if (!reason.empty()) self->last_os_reason = reason;
    H5Eprint2(stack, self->log);
    std::fflush(self->log);
    return 0;
  }
};

Hdf5ErrorLog::Hdf5ErrorLog(std::FILE* log) : state_(std::make_unique<State>()) {
  state_->log = log;
  H5Eget_auto2(H5E_DEFAULT, &state_->saved_func, &state_->saved_data);
  H5Eset_auto2(H5E_DEFAULT, State::on_error, state_.get());
}

Hdf5ErrorLog::~Hdf5ErrorLog() {
  H5Eset_auto2(H5E_DEFAULT, state_->saved_func, state_->saved_data);
}

long Hdf5ErrorLog::errors() const {
  return state_->errors;
}
const std::string& Hdf5ErrorLog::last_os_reason() const {
  return state_->last_os_reason;
}

}  // namespace sheardiff
