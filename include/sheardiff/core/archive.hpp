#pragma once
// A symmetric binary archive for checkpoints: the same serialize(Archive&) member saves and
// loads, so what is written is what is read. Only for trivially copyable values, vectors and
// strings; the file format is this machine's (checkpoints resume on the machine kind that wrote
// them).
#include <Eigen/Core>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace sheardiff {

class Archive {
 public:
  // The state layout this sheardiff writes (the digit of a checkpoint's magic): a section whose
  // shape changed reads an older layout's by asking layout().
  static constexpr int kLayout = 9;
  static Archive writer() { return Archive(false, {}, kLayout); }
  static Archive reader(std::vector<char> bytes, int layout = kLayout) {
    return Archive(true, std::move(bytes), layout);
  }

  bool loading() const { return loading_; }
  int layout() const { return layout_; }
  const std::vector<char>& bytes() const { return buf_; }
  bool at_end() const { return pos_ == buf_.size(); }

  template <class T>
  requires(std::is_trivially_copyable_v<T> &&
           !requires(T & t, Archive& a) { t.serialize(a); }) void io(T& x) {
    raw(&x, sizeof(T));
  }
  template <class T>
  void io(std::vector<T>& v) {
    std::uint64_t n = v.size();
    io(n);
    // Each element takes at least one byte (its size if trivially copyable): a length beyond
    // what is left is a corrupt file, not a reason to allocate.
    if (loading_) {
      check_length(n, std::is_trivially_copyable_v<T> ? sizeof(T) : 1);
      v.resize(n);
    }
    if constexpr (std::is_trivially_copyable_v<T>) {
      raw(v.data(), n * sizeof(T));
    } else {
      for (auto& x : v) io(x);
    }
  }
  template <class S, int R, int C, int O, int MR, int MC>
  requires(R > 0 && C > 0) void io(Eigen::Matrix<S, R, C, O, MR, MC>& m) {
    raw(m.data(), sizeof(S) * R * C);
  }
  void io(std::vector<bool>& v) {
    std::vector<std::uint8_t> b(v.begin(), v.end());
    io(b);
    if (loading_) v.assign(b.begin(), b.end());
  }
  void io(std::string& s) {
    std::uint64_t n = s.size();
    io(n);
    if (loading_) {
      check_length(n, 1);
      s.resize(n);
    }
    raw(s.data(), n);
  }
  template <class T>
  requires requires(T& t, Archive& a) { t.serialize(a); }
  void io(T& x) { x.serialize(*this); }
  // A named check point inside the stream: a mismatch means a corrupt or foreign file.
  void tag(const char* name) {
    std::string s = name;
    std::string got = s;
    io(got);
    if (got != s)
      throw std::runtime_error("checkpoint: expected section '" + s + "', found '" + got + "'");
  }

 private:
  Archive(bool loading, std::vector<char> bytes, int layout)
      : loading_(loading), layout_(layout), buf_(std::move(bytes)) {}
  void check_length(std::uint64_t n, std::size_t bytes_each) const {
    if (n > (buf_.size() - pos_) / bytes_each)
      throw std::runtime_error("checkpoint: a length field of " + std::to_string(n) +
                               " elements exceeds the " + std::to_string(buf_.size() - pos_) +
                               " bytes left in the file");
  }
  void raw(void* p, std::size_t n) {
    if (n == 0) return;  // an empty vector's data() may be null: memcpy(null, ...) is UB
    if (loading_) {
      if (pos_ + n > buf_.size()) throw std::runtime_error("checkpoint: file is truncated");
      std::memcpy(p, buf_.data() + pos_, n);
      pos_ += n;
    } else {
      const char* c = static_cast<const char*>(p);
      buf_.insert(buf_.end(), c, c + n);
    }
  }
  bool loading_;
  int layout_;
  std::vector<char> buf_;
  std::size_t pos_ = 0;
};

}  // namespace sheardiff
