#include "sheardiff/io/h5md.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <hdf5.h>
#include <pwd.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <type_traits>
#include <utility>

#include "sheardiff/io/hdf5_diagnostics.hpp"
#include "sheardiff/io/io_error.hpp"

namespace sheardiff {

namespace fs = std::filesystem;

namespace {

constexpr const char* kSuspension = "/particles/suspension";
constexpr hsize_t kScalarChunk = 1024;
constexpr unsigned kDeflateLevel = 1;

using Closer = herr_t (*)(hid_t);

// Owns one hid_t and closes it with the matching H5?close.
class Handle {
 public:
  Handle() = default;
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Handle(Handle&& o) noexcept : id_(std::exchange(o.id_, H5I_INVALID_HID)), closer_(o.closer_) {}
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, H5I_INVALID_HID);
      closer_ = o.closer_;
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { reset(); }

  void reset() noexcept {
    if (id_ >= 0 && closer_ != nullptr) closer_(id_);
    id_ = H5I_INVALID_HID;
  }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer closer_ = nullptr;
};

// HDF5 prints its error stack to stderr on failure; where we turn the failure into an
// exception anyway (opening/creating files), suppress the print and restore afterwards.
class ErrorPrintGuard {
 public:
  ErrorPrintGuard() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~ErrorPrintGuard() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  ErrorPrintGuard(const ErrorPrintGuard&) = delete;
  ErrorPrintGuard& operator=(const ErrorPrintGuard&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

[[noreturn]] void fail(const fs::path& file, std::string_view object, std::string_view what) {
  const std::string reason = hdf5_os_reason();
  throw IoError(fmt::format("H5MD file '{}', object '{}': {}{}{}", file.string(), object, what,
                            reason.empty() ? "" : ": ", reason));
}

Handle checked(hid_t id, Closer closer, const fs::path& file, std::string_view object,
               std::string_view what) {
  if (id < 0) fail(file, object, what);
  return Handle(id, closer);
}

void check(herr_t rc, const fs::path& file, std::string_view object, std::string_view what) {
  if (rc < 0) fail(file, object, what);
}

Handle simple_space(const std::vector<hsize_t>& dims, const std::vector<hsize_t>* maxdims,
                    const fs::path& file, std::string_view object) {
  return checked(H5Screate_simple(static_cast<int>(dims.size()), dims.data(),
                                  maxdims != nullptr ? maxdims->data() : nullptr),
                 H5Sclose, file, object, "cannot create dataspace");
}

Handle create_group(hid_t loc, const std::string& full, const fs::path& file) {
  return checked(H5Gcreate2(loc, full.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                 file, full, "cannot create group");
}

// Variable-length strings keep large values (the config text) out of the 64 kB object header.
// H5MD 1.1 asks for fixed-length strings in /h5md and box/boundary, and the units module for
// variable-length ASCII in `unit`.
enum class Str { VlUtf8, VlAscii, Fixed };

void write_string_attr(hid_t obj, const std::string& obj_name, const char* attr,
                       const std::vector<std::string>& values, bool scalar, const fs::path& file,
                       Str kind = Str::VlUtf8) {
  const std::string where = obj_name + "@" + attr;
  Handle type = checked(H5Tcopy(H5T_C_S1), H5Tclose, file, where, "cannot create string type");
  std::size_t longest = 1;
  for (const auto& v : values) longest = std::max(longest, v.size() + 1);
  check(H5Tset_size(type.get(), kind == Str::Fixed ? longest : H5T_VARIABLE), file, where,
        "cannot create string type");
  if (kind == Str::Fixed) check(H5Tset_strpad(type.get(), H5T_STR_NULLTERM), file, where, "pad");
  check(H5Tset_cset(type.get(), kind == Str::VlUtf8 ? H5T_CSET_UTF8 : H5T_CSET_ASCII), file, where,
        "cannot create string type");
  Handle space =
      scalar ? checked(H5Screate(H5S_SCALAR), H5Sclose, file, where, "cannot create dataspace")
             : simple_space({values.size()}, nullptr, file, where);
  Handle a = checked(H5Acreate2(obj, attr, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
                     H5Aclose, file, where, "cannot create attribute");
  if (kind == Str::Fixed) {
    std::vector<char> buf(longest * values.size(), '\0');
    for (std::size_t k = 0; k < values.size(); ++k)
      std::copy(values[k].begin(), values[k].end(), buf.begin() + k * longest);
    check(H5Awrite(a.get(), type.get(), buf.data()), file, where, "cannot write attribute");
    return;
  }
  std::vector<const char*> ptrs;
  ptrs.reserve(values.size());
  for (const auto& v : values) ptrs.push_back(v.c_str());
  check(H5Awrite(a.get(), type.get(), ptrs.data()), file, where, "cannot write attribute");
}

void write_unit(hid_t obj, const std::string& obj_name, const std::string& unit,
                const fs::path& file) {
  write_string_attr(obj, obj_name, "unit", {unit}, true, file, Str::VlAscii);
}

void write_int_attr(hid_t obj, const std::string& obj_name, const char* attr,
                    const std::vector<int>& values, bool scalar, const fs::path& file) {
  const std::string where = obj_name + "@" + attr;
  Handle space =
      scalar ? checked(H5Screate(H5S_SCALAR), H5Sclose, file, where, "cannot create dataspace")
             : simple_space({values.size()}, nullptr, file, where);
  Handle a = checked(H5Acreate2(obj, attr, H5T_STD_I32LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                     H5Aclose, file, where, "cannot create attribute");
  check(H5Awrite(a.get(), H5T_NATIVE_INT, values.data()), file, where, "cannot write attribute");
}

// An HDF5 enumeration names its codes in the file itself (H5MD allows Enumeration for species).
Handle enum_type(const std::vector<std::pair<const char*, std::int8_t>>& members,
                 const fs::path& file, std::string_view object) {
  Handle t = checked(H5Tenum_create(H5T_STD_I8LE), H5Tclose, file, object,
                     "cannot create enumeration type");
  for (const auto& [name, value] : members)
    check(H5Tenum_insert(t.get(), name, &value), file, object, "cannot create enumeration type");
  return t;
}

template <class T>
Handle write_fixed_dataset(hid_t loc, const std::string& full, hid_t file_type, hid_t mem_type,
                           const std::vector<hsize_t>& dims, const T* data, const std::string& unit,
                           const fs::path& file) {
  Handle space = simple_space(dims, nullptr, file, full);
  Handle ds = checked(
      H5Dcreate2(loc, full.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
      H5Dclose, file, full, "cannot create dataset");
  hsize_t n = 1;
  for (hsize_t d : dims) n *= d;
  if (n > 0) {
    check(H5Dwrite(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), file, full,
          "cannot write dataset");
  }
  write_unit(ds.get(), full, unit, file);
  return ds;
}

// A dataset growing by one row per frame along an unlimited first dimension. A ragged series
// (the contacts) also grows along its second dimension; entries past a row's length keep the
// dataset's fill value.
struct Series {
  Handle ds;
  std::string name;
  std::vector<hsize_t> inner;  // shape of one row
  hsize_t rows = 0;
  bool ragged = false;

  void append(hid_t mem_type, const void* data, const fs::path& file, hsize_t length = 0) {
    std::vector<hsize_t> dims{rows + 1};
    if (ragged) inner[0] = std::max(inner[0], length);
    dims.insert(dims.end(), inner.begin(), inner.end());
    check(H5Dset_extent(ds.get(), dims.data()), file, name, "cannot extend dataset");
    std::vector<hsize_t> count = dims;
    count[0] = 1;
    if (ragged) count[1] = length;
    hsize_t n = 1;
    for (hsize_t c : count) n *= c;
    if (n > 0) {
      Handle fspace = checked(H5Dget_space(ds.get()), H5Sclose, file, name, "cannot get dataspace");
      std::vector<hsize_t> start(dims.size(), 0);
      start[0] = rows;
      check(H5Sselect_hyperslab(fspace.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(),
                                nullptr),
            file, name, "cannot select row");
      Handle mspace = simple_space(count, nullptr, file, name);
      check(H5Dwrite(ds.get(), mem_type, mspace.get(), fspace.get(), H5P_DEFAULT, data), file, name,
            "cannot write row");
    }
    ++rows;
  }
};

Series create_series(hid_t loc, const std::string& full, hid_t file_type,
                     std::vector<hsize_t> inner, hsize_t chunk_rows, const fs::path& file,
                     const void* fill = nullptr) {
  const bool ragged = fill != nullptr;  // only the contact datasets are ragged, and have a fill
  std::vector<hsize_t> dims{0};
  dims.insert(dims.end(), inner.begin(), inner.end());
  std::vector<hsize_t> maxdims = dims;
  maxdims[0] = H5S_UNLIMITED;
  std::vector<hsize_t> chunk = dims;
  chunk[0] = chunk_rows;
  if (ragged) {
    maxdims[1] = H5S_UNLIMITED;
    chunk[1] = 512;
  }

  Handle space = simple_space(dims, &maxdims, file, full);
  Handle dcpl =
      checked(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, file, full, "cannot create property list");
  check(H5Pset_chunk(dcpl.get(), static_cast<int>(chunk.size()), chunk.data()), file, full,
        "cannot set chunking");
  if (fill != nullptr)
    check(H5Pset_fill_value(dcpl.get(), file_type, fill), file, full, "cannot set fill value");
  // Per-frame series are shuffled and deflated. Only they: each of their chunks (one frame) is
  // written once, whereas a compressed chunk of many frames would be rewritten, to a new place,
  // at every flush, and a kill between the write and the index update could lose frames a
  // checkpoint already counts. The scalar series (many frames a chunk) are small and stay
  // uncompressed, rewritten in place.
  if (chunk_rows == 1) {
    check(H5Pset_shuffle(dcpl.get()), file, full, "cannot set the shuffle filter");
    check(H5Pset_deflate(dcpl.get(), kDeflateLevel), file, full, "cannot set compression");
  }
  Series s;
  s.ds = checked(
      H5Dcreate2(loc, full.c_str(), file_type, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
      H5Dclose, file, full, "cannot create dataset");
  s.name = full;
  s.inner = std::move(inner);
  s.ragged = ragged;
  return s;
}

// Opens an existing series, checks its row shape and cuts it back to `rows` rows.
Series open_series(hid_t loc, const std::string& full, std::vector<hsize_t> inner, hsize_t rows,
                   const fs::path& file, bool ragged = false) {
  Series s;
  s.ds = checked(H5Dopen2(loc, full.c_str(), H5P_DEFAULT), H5Dclose, file, full,
                 "cannot open dataset");
  s.name = full;
  s.ragged = ragged;
  Handle space = checked(H5Dget_space(s.ds.get()), H5Sclose, file, full, "cannot get dataspace");
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 1) fail(file, full, "expected rank >= 1");
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  std::vector<hsize_t> have_inner(dims.begin() + 1, dims.end());
  if (ragged && !have_inner.empty() && !inner.empty()) inner[0] = have_inner[0];
  if (have_inner != inner)
    fail(file, full,
         fmt::format("row shape ({}) differs from this version's ({}): the trajectory was "
                     "written by another sheardiff version and cannot be continued",
                     fmt::join(have_inner, ", "), fmt::join(inner, ", ")));
  if (dims[0] < rows)
    fail(file, full, fmt::format("holds {} rows, the checkpoint needs {}", dims[0], rows));
  dims[0] = rows;
  check(H5Dset_extent(s.ds.get(), dims.data()), file, full, "cannot truncate dataset");
  s.inner = std::move(inner);
  s.rows = rows;
  return s;
}

void hard_link(hid_t f, const std::string& target, const std::string& link, const fs::path& file) {
  check(H5Lcreate_hard(f, target.c_str(), f, link.c_str(), H5P_DEFAULT, H5P_DEFAULT), file, link,
        "cannot create hard link to " + target);
}

void check_name(const std::string& name, const fs::path& file, std::string_view what) {
  if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..") {
    fail(file, "/observables/" + name, fmt::format("invalid {} name", what));
  }
}

// Read-only access with existence checks, so missing objects give a clean message; HDF5's own
// error printing is off while a Reader lives (a foreign file's layout is no reason for noise).
class Reader {
 public:
  explicit Reader(const fs::path& path) : path_(path) {
    std::error_code ec;
    if (!fs::exists(path_, ec)) fail(path_, "/", "file does not exist");
    file_ = checked(H5Fopen(path_.string().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, path_,
                    "/", "cannot open file as HDF5");
  }

  const fs::path& path() const { return path_; }
  hid_t id() const { return file_.get(); }

  // H5Lexists fails (not false) below a missing or non-group component, so walk them.
  bool exists(const std::string& name) const {
    std::size_t pos = 0;
    while (pos != std::string::npos) {
      pos = name.find('/', pos + 1);
      const std::string prefix = name.substr(0, pos);
      if (H5Lexists(file_.get(), prefix.c_str(), H5P_DEFAULT) <= 0) return false;
      if (pos != std::string::npos && !is_group(prefix)) return false;
    }
    return true;
  }

  Handle open_dataset(const std::string& name) const {
    if (!exists(name)) fail(path_, name, "object not found");
    return checked(H5Dopen2(file_.get(), name.c_str(), H5P_DEFAULT), H5Dclose, path_, name,
                   "cannot open dataset");
  }

  std::vector<hsize_t> dims(const std::string& name) const {
    Handle ds = open_dataset(name);
    return dims_of(ds.get(), name);
  }

  hsize_t rows(const std::string& name) const {
    const auto d = dims(name);
    if (d.empty()) fail(path_, name, "expected a dataset of rank >= 1");
    return d[0];
  }

  bool is_group(const std::string& name) const {
    H5O_info_t info;
    if (H5Oget_info_by_name2(file_.get(), name.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT) < 0) {
      fail(path_, name, "cannot query object");
    }
    return info.type == H5O_TYPE_GROUP;
  }

  std::vector<std::string> children(const std::string& group) const {
    H5G_info_t info;
    if (H5Gget_info_by_name(file_.get(), group.c_str(), &info, H5P_DEFAULT) < 0)
      fail(path_, group, "cannot list group");
    std::vector<std::string> out;
    for (hsize_t k = 0; k < info.nlinks; ++k) {
      const ssize_t len = H5Lget_name_by_idx(file_.get(), group.c_str(), H5_INDEX_NAME, H5_ITER_INC,
                                             k, nullptr, 0, H5P_DEFAULT);
      if (len < 0) fail(path_, group, "cannot list group");
      std::string name(static_cast<std::size_t>(len) + 1, '\0');
      H5Lget_name_by_idx(file_.get(), group.c_str(), H5_INDEX_NAME, H5_ITER_INC, k, name.data(),
                         name.size(), H5P_DEFAULT);
      name.resize(static_cast<std::size_t>(len));
      out.push_back(name);
    }
    return out;
  }

  // Fixed- or variable-length string attribute, as a list.
  std::vector<std::string> string_attr(const std::string& obj, const char* attr) const {
    const std::string where = obj + "@" + attr;
    if (H5Aexists_by_name(file_.get(), obj.c_str(), attr, H5P_DEFAULT) <= 0)
      fail(path_, where, "attribute not found");
    Handle a = checked(H5Aopen_by_name(file_.get(), obj.c_str(), attr, H5P_DEFAULT, H5P_DEFAULT),
                       H5Aclose, path_, where, "cannot open attribute");
    Handle type = checked(H5Aget_type(a.get()), H5Tclose, path_, where, "cannot get type");
    if (H5Tget_class(type.get()) != H5T_STRING) fail(path_, where, "not a string attribute");
    Handle space = checked(H5Aget_space(a.get()), H5Sclose, path_, where, "cannot get dataspace");
    const hssize_t n = H5Sget_simple_extent_npoints(space.get());
    if (n < 0) fail(path_, where, "cannot get size");
    std::vector<std::string> out;
    if (H5Tis_variable_str(type.get()) > 0) {
      Handle mem = checked(H5Tcopy(H5T_C_S1), H5Tclose, path_, where, "cannot create type");
      H5Tset_size(mem.get(), H5T_VARIABLE);
      H5Tset_cset(mem.get(), H5Tget_cset(type.get()));
      std::vector<char*> ptrs(static_cast<std::size_t>(n), nullptr);
      check(H5Aread(a.get(), mem.get(), ptrs.data()), path_, where, "cannot read attribute");
      for (char* p : ptrs) {
        out.emplace_back(p != nullptr ? p : "");
        H5free_memory(p);
      }
    } else {
      const std::size_t size = H5Tget_size(type.get());
      std::vector<char> buf(size * static_cast<std::size_t>(n) + 1, '\0');
      check(H5Aread(a.get(), type.get(), buf.data()), path_, where, "cannot read attribute");
      for (hssize_t k = 0; k < n; ++k) {
        std::string v(buf.data() + static_cast<std::size_t>(k) * size, size);
        v.resize(std::min(v.find('\0'), v.find_last_not_of(' ') + 1));
        out.push_back(v);
      }
    }
    return out;
  }

  // Rows [first, first+count) along dimension 0, flattened; `inner` receives the row shape.
  template <class T>
  std::vector<T> read_rows(const std::string& name, hid_t mem_type, hsize_t first, hsize_t count,
                           std::vector<hsize_t>* inner = nullptr) const {
    Handle ds = open_dataset(name);
    const auto d = dims_of(ds.get(), name);
    if (d.empty()) fail(path_, name, "expected a dataset of rank >= 1");
    if (first + count > d[0]) {
      fail(path_, name,
           fmt::format("row range [{}, {}) beyond {} rows", first, first + count, d[0]));
    }
    std::vector<hsize_t> start(d.size(), 0), cnt = d;
    start[0] = first;
    cnt[0] = count;
    hsize_t n = 1;
    for (hsize_t c : cnt) n *= c;
    if (inner != nullptr) inner->assign(d.begin() + 1, d.end());
    std::vector<T> out(n);
    if (n == 0) return out;
    Handle fspace = checked(H5Dget_space(ds.get()), H5Sclose, path_, name, "cannot get dataspace");
    check(H5Sselect_hyperslab(fspace.get(), H5S_SELECT_SET, start.data(), nullptr, cnt.data(),
                              nullptr),
          path_, name, "cannot select rows");
    Handle mspace = simple_space(cnt, nullptr, path_, name);
    check(H5Dread(ds.get(), mem_type, mspace.get(), fspace.get(), H5P_DEFAULT, out.data()), path_,
          name, "cannot read dataset");
    return out;
  }

  template <class T>
  std::vector<T> read_all(const std::string& name, hid_t mem_type,
                          std::vector<hsize_t>* inner = nullptr) const {
    const auto d = dims(name);
    if (d.empty()) {  // scalar dataspace
      Handle ds = open_dataset(name);
      std::vector<T> out(1);
      check(H5Dread(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), path_, name,
            "cannot read dataset");
      if (inner != nullptr) inner->clear();
      return out;
    }
    return read_rows<T>(name, mem_type, 0, d[0], inner);
  }

  template <class T>
  std::optional<T> scalar_attr(const std::string& obj, const char* attr, hid_t mem_type) const {
    if (H5Aexists_by_name(file_.get(), obj.c_str(), attr, H5P_DEFAULT) <= 0) return std::nullopt;
    Handle a = checked(H5Aopen_by_name(file_.get(), obj.c_str(), attr, H5P_DEFAULT, H5P_DEFAULT),
                       H5Aclose, path_, obj + "@" + attr, "cannot open attribute");
    T v{};
    check(H5Aread(a.get(), mem_type, &v), path_, obj + "@" + attr, "cannot read attribute");
    return v;
  }

 private:
  std::vector<hsize_t> dims_of(hid_t ds, const std::string& name) const {
    Handle space = checked(H5Dget_space(ds), H5Sclose, path_, name, "cannot get dataspace");
    const int rank = H5Sget_simple_extent_ndims(space.get());
    if (rank < 0) fail(path_, name, "cannot get rank");
    std::vector<hsize_t> d(static_cast<std::size_t>(rank));
    if (rank > 0 && H5Sget_simple_extent_dims(space.get(), d.data(), nullptr) < 0) {
      fail(path_, name, "cannot get dimensions");
    }
    return d;
  }

  ErrorPrintGuard quiet_;  // first: restored after the file is closed
  fs::path path_;
  Handle file_;
};

std::string susp(const char* rel) {
  return std::string(kSuspension) + "/" + rel;
}

// The particle group to read: ours ("suspension"), the common "all", or the only one.
std::string particle_group(const Reader& r) {
  if (!r.exists("/particles") || !r.is_group("/particles"))
    fail(r.path(), "/particles", "group not found");
  const auto names = r.children("/particles");
  for (const char* preferred : {"suspension", "all"})
    if (std::find(names.begin(), names.end(), preferred) != names.end())
      return std::string("/particles/") + preferred;
  if (names.size() == 1) return "/particles/" + names[0];
  fail(r.path(), "/particles",
       fmt::format("holds the groups [{}]; expected one, or one named \"suspension\" or \"all\"",
                   fmt::join(names, ", ")));
}

// Rows of a time-dependent element: value's, cut to explicit step and time (a crash may
// leave them a row apart in files written without hard links).
hsize_t element_rows(const Reader& r, const std::string& element) {
  hsize_t n = r.rows(element + "/value");
  for (const char* axis : {"/step", "/time"}) {
    const std::string name = element + axis;
    if (!r.exists(name)) continue;
    const auto d = r.dims(name);
    if (!d.empty()) n = std::min(n, d[0]);
  }
  return n;
}

long count_frames(const Reader& r, const std::string& group) {
  hsize_t n = element_rows(r, group + "/position");
  const std::string edges = group + "/box/edges";
  if (r.exists(edges) && r.is_group(edges)) n = std::min(n, element_rows(r, edges));
  return static_cast<long>(n);
}

// Step or time of row idx, in either H5MD 1.1 storage mode (explicit, or fixed increment
// with an optional offset).
template <class T>
T axis_value(const Reader& r, const std::string& name, hid_t mem_type, hsize_t idx) {
  if (r.dims(name).empty()) {
    const T inc = r.read_all<T>(name, mem_type)[0];
    const T offset = r.scalar_attr<T>(name, "offset", mem_type).value_or(T{});
    return static_cast<T>(idx) * inc + offset;
  }
  return r.read_rows<T>(name, mem_type, idx, 1)[0];
}

std::vector<Vec2> to_vec2(const std::vector<double>& flat, std::size_t dim) {
  std::vector<Vec2> out(flat.size() / dim);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = Vec2(flat[dim * i], flat[dim * i + 1]);
  return out;
}

void expect_shape(const Reader& r, const std::string& name, const std::vector<hsize_t>& got,
                  const std::vector<hsize_t>& want) {
  if (got != want) {
    fail(r.path(), name,
         fmt::format("unexpected shape ({}), expected ({})", fmt::join(got, ", "),
                     fmt::join(want, ", ")));
  }
}

// Units in the project's reduced units (docs/units.md, docs/trajectory.md): d the small
// diameter, P the imposed pressure, eta the fluid viscosity.
constexpr const char* kLength = "d";
constexpr const char* kTime = "eta P-1";
constexpr const char* kVelocity = "P d eta-1";
constexpr const char* kRate = "P eta-1";
constexpr const char* kForce = "P d+2";
constexpr const char* kNumber = "1";

}  // namespace

// ---------------------------------------------------------------------------------------
// Writer

namespace {

const std::string kStep = susp("position/step");
const std::string kTimeName = susp("position/time");
constexpr const char* kContacts = "/connectivity/contacts";

std::string author_name(const std::string& given) {
  if (!given.empty()) return given;
  if (const char* env = std::getenv("SHEARDIFF_AUTHOR"); env != nullptr && *env != '\0') return env;
  // The real name of the passwd entry (its first GECOS field), else the login.
  if (const passwd* pw = getpwuid(getuid()); pw != nullptr) {
    std::string gecos = pw->pw_gecos != nullptr ? pw->pw_gecos : "";
    gecos = gecos.substr(0, gecos.find(','));
    if (!gecos.empty()) return gecos;
    if (pw->pw_name != nullptr && *pw->pw_name != '\0') return pw->pw_name;
  }
  return "unknown";
}

// Where the Lees-Edwards shift is reduced to [-lx/2, lx/2] (LAMMPS's limit; the same lattice).
double reduced_tilt(double tilt, double lx) {
  return tilt - lx * std::round(tilt / lx);
}

}  // namespace

struct H5mdWriter::Impl {
  fs::path path;
  TrajectoryLayout layout;
  Handle file;  // declared first so it is closed after all objects inside it
  // position's step and time: every other time-dependent element hard-links them.
  Series step, time;
  Series edges, position, velocity, angular_velocity;
  std::optional<Series> image, unwrapped;
  std::vector<Series> observables;
  std::optional<Series> pairs, normal_force, tangential_force, sliding;
  long frames = 0;
  double max_diameter = 0;
  // Single-writer/multiple-reader mode: readers (h5py with swmr=True, tools/rundir.py) follow the
  // file while frames are appended. Entered once every dataset exists (after the first frame),
  // left before the end of the run adds its tables (SWMR cannot create objects).
  bool swmr = false, swmr_tried = false, frames_closed = false;

  ~Impl() {
    if (file.valid()) H5Fflush(file.get(), H5F_SCOPE_LOCAL);
  }

  // An element group whose step and time are position's and whose value is a new series.
  Series element(const std::string& full, hid_t file_type, std::vector<hsize_t> inner,
                 hsize_t chunk_rows, const std::string& unit) {
    const hid_t f = file.get();
    Handle g = create_group(f, full, path);
    hard_link(f, kStep, full + "/step", path);
    hard_link(f, kTimeName, full + "/time", path);
    Series s = create_series(f, full + "/value", file_type, std::move(inner), chunk_rows, path);
    write_unit(s.ds.get(), s.name, unit, path);
    return s;
  }

  void start_swmr();
  void leave_swmr();
  void create_suspension();
  void create_observables();
  void create_contacts();
  void check_frame(const FrameData& frame, bool want_images, bool want_unwrapped) const;
  void append_images(const FrameData& frame, double tilt, double ly);
  void append_sphere_images(const FrameData& frame);
  void append_velocity(const FrameData& frame);
  void append_contacts(const ContactNetwork& c);

  // The image counts of every particle, and its unwrapped position where that is not derivable
  // from them (Lees-Edwards: x differs by the shift gained since each crossing).
  void create_images(bool with_unwrapped) {
    const hsize_t n = layout.n_particles;
    const auto dim = static_cast<hsize_t>(layout.dimension);
    image = element(susp("image"), H5T_STD_I32LE, {n, dim}, 1, kNumber);
    if (with_unwrapped)
      unwrapped = element(susp("unwrapped_position"), H5T_IEEE_F64LE, {n, dim}, 1, kLength);
  }
};

namespace {

// Whether the layout can be written: sizes agree, observable names are valid and distinct.
void check_layout(const fs::path& path, const TrajectoryLayout& layout) {
  const std::size_t n = layout.n_particles;
  if (n == 0) fail(path, kSuspension, "layout has no particles");
  if (layout.dimension != 2 && layout.dimension != 3)
    fail(path, susp("box"), fmt::format("dimension {} is neither 2 nor 3", layout.dimension));
  if (layout.species.size() != n || layout.diameter.size() != n || layout.motion.size() != n) {
    fail(path, kSuspension,
         fmt::format("layout arrays sizes species={} diameter={} motion={} != n_particles={}",
                     layout.species.size(), layout.diameter.size(), layout.motion.size(), n));
  }
  if (!layout.observable_units.empty() &&
      layout.observable_units.size() != layout.observables.size())
    fail(path, "/observables",
         fmt::format("{} units for {} observables", layout.observable_units.size(),
                     layout.observables.size()));
  for (std::size_t i = 0; i < layout.observables.size(); ++i) {
    check_name(layout.observables[i], path, "observable");
    for (std::size_t j = 0; j < i; ++j) {
      if (layout.observables[j] == layout.observables[i]) {
        fail(path, "/observables/" + layout.observables[i], "duplicate observable name");
      }
    }
  }
}

// /h5md (version, author, creator, units module) and /parameters (the run's configuration).
void write_h5md_header(hid_t f, const fs::path& path, const TrajectoryLayout& layout) {
  {
    Handle h5md = create_group(f, "/h5md", path);
    write_int_attr(h5md.get(), "/h5md", "version", {1, 1}, false, path);
    Handle author = create_group(f, "/h5md/author", path);
    write_string_attr(author.get(), "/h5md/author", "name", {author_name(layout.author)}, true,
                      path, Str::Fixed);
    Handle creator = create_group(f, "/h5md/creator", path);
    write_string_attr(creator.get(), "/h5md/creator", "name", {"sheardiff"}, true, path,
                      Str::Fixed);
    write_string_attr(creator.get(), "/h5md/creator", "version", {layout.creator_version}, true,
                      path, Str::Fixed);
    Handle modules = create_group(f, "/h5md/modules", path);
    Handle units = create_group(f, "/h5md/modules/units", path);
    write_int_attr(units.get(), "/h5md/modules/units", "version", {1, 0}, false, path);
    write_string_attr(units.get(), "/h5md/modules/units", "system", {"reduced"}, true, path,
                      Str::VlAscii);
    write_string_attr(units.get(), "/h5md/modules/units", "symbols",
                      {"d: diameter of the small particles; P: imposed (reference) pressure; "
                       "eta: viscosity of the suspending fluid; 1: dimensionless"},
                      true, path);
  }
  {
    Handle parameters = create_group(f, "/parameters", path);
    write_string_attr(parameters.get(), "/parameters", "config", {layout.config_toml}, true, path);
  }
}

}  // namespace

namespace {

// The latest file format: what single-writer/multiple-reader mode needs (HDF5 >= 1.10 reads it).
Handle latest_format(const fs::path& path) {
  Handle fapl = checked(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, path, "/", "cannot create fapl");
  check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_LATEST, H5F_LIBVER_LATEST), path, "/",
        "cannot set the file format");
  return fapl;
}

}  // namespace

void H5mdWriter::Impl::start_swmr() {
  if (swmr_tried) return;
  swmr_tried = true;
  // A trajectory begun in the older format (before this mode) is continued without it.
  ErrorPrintGuard quiet;
  swmr = H5Fstart_swmr_write(file.get()) >= 0;
}

// Closes every series and reopens the file for writing objects; no frame is written after.
void H5mdWriter::Impl::leave_swmr() {
  if (!swmr) return;
  check(H5Fflush(file.get(), H5F_SCOPE_LOCAL), path, "/", "cannot flush file");
  for (Series* s : {&step, &time, &edges, &position, &velocity, &angular_velocity}) s->ds.reset();
  for (auto* s : {&image, &unwrapped, &pairs, &normal_force, &tangential_force, &sliding})
    s->reset();
  observables.clear();
  file.reset();
  Handle fapl = latest_format(path);
  ErrorPrintGuard quiet;
  file = checked(H5Fopen(path.string().c_str(), H5F_ACC_RDWR, fapl.get()), H5Fclose, path, "/",
                 "cannot reopen the trajectory to write its tables");
  swmr = false;
  frames_closed = true;
}

// /particles/suspension: the box, the position series (whose step and time every element
// links), velocities where written, and the per-particle constants (species, motion, diameter).
void H5mdWriter::Impl::create_suspension() {
  const hid_t f = file.get();
  const std::size_t n = layout.n_particles;
  const auto dim = static_cast<hsize_t>(layout.dimension);
  Handle particles = create_group(f, "/particles", path);
  Handle suspension = create_group(f, kSuspension, path);
  {
    const std::string box_name = susp("box");
    Handle box = create_group(f, box_name, path);
    write_int_attr(box.get(), box_name, "dimension", {layout.dimension}, true, path);
    std::vector<std::string> boundary = {"periodic", layout.lees_edwards ? "periodic" : "none"};
    if (dim == 3) boundary.push_back("periodic");
    write_string_attr(box.get(), box_name, "boundary", boundary, false, path, Str::Fixed);
  }
  {
    Handle position_group = create_group(f, susp("position"), path);
    step = create_series(f, kStep, H5T_STD_I64LE, {}, kScalarChunk, path);
    time = create_series(f, kTimeName, H5T_IEEE_F64LE, {}, kScalarChunk, path);
    write_unit(time.ds.get(), kTimeName, kTime, path);
    position = create_series(f, susp("position/value"), H5T_IEEE_F64LE, {n, dim}, 1, path);
    write_unit(position.ds.get(), position.name, kLength, path);
  }
  edges = element(susp("box/edges"), H5T_IEEE_F64LE, {dim, dim}, kScalarChunk, kLength);
  if (layout.write_velocity) {
    velocity = element(susp("velocity"), H5T_IEEE_F64LE, {n, dim}, 1, kVelocity);
    // omega_z of a disc, the vector omega of a sphere
    angular_velocity =
        element(susp("angular_velocity"), H5T_IEEE_F64LE,
                dim == 3 ? std::vector<hsize_t>{n, 3} : std::vector<hsize_t>{n}, 1, kRate);
  }
  {
    // HDF5 converts enumerations to numbers on reading, not numbers to enumerations.
    const auto codes = [](const std::vector<int>& v) {
      return std::vector<std::int8_t>(v.begin(), v.end());
    };
    Handle species = enum_type({{"small", 0}, {"large", 1}}, path, susp("species"));
    write_fixed_dataset(f, susp("species"), species.get(), species.get(), {n},
                        codes(layout.species).data(), kNumber, path);
    Handle motion =
        enum_type({{"mobile", 0}, {"fixed_wall", 1}, {"floating_wall", 2}, {"driven_wall", 3}},
                  path, susp("motion"));
    write_fixed_dataset(f, susp("motion"), motion.get(), motion.get(), {n},
                        codes(layout.motion).data(), kNumber, path);
  }
  write_fixed_dataset(f, susp("diameter"), H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n},
                      layout.diameter.data(), kLength, path);
}

void H5mdWriter::Impl::create_observables() {
  const hid_t f = file.get();
  Handle obs_group = create_group(f, "/observables", path);
  for (std::size_t k = 0; k < layout.observables.size(); ++k) {
    const std::string unit = layout.observable_units.empty() ? kNumber : layout.observable_units[k];
    observables.push_back(
        element("/observables/" + layout.observables[k], H5T_IEEE_F64LE, {}, kScalarChunk, unit));
  }
}

// /connectivity/contacts: ragged per-frame lists of pairs and their forces, linked to the
// particle group.
void H5mdWriter::Impl::create_contacts() {
  const hid_t f = file.get();
  Handle connectivity = create_group(f, "/connectivity", path);
  Handle contacts = create_group(f, kContacts, path);
  hobj_ref_t ref;
  check(H5Rcreate(&ref, f, kSuspension, H5R_OBJECT, -1), path, kContacts,
        "cannot reference the particle group");
  {
    const std::string where = std::string(kContacts) + "@particles_group";
    Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, path, where, "dataspace");
    Handle a = checked(H5Acreate2(contacts.get(), "particles_group", H5T_STD_REF_OBJ, space.get(),
                                  H5P_DEFAULT, H5P_DEFAULT),
                       H5Aclose, path, where, "cannot create attribute");
    check(H5Awrite(a.get(), H5T_STD_REF_OBJ, &ref), path, where, "cannot write attribute");
  }
  const std::string c = kContacts;
  hard_link(f, kStep, c + "/step", path);
  hard_link(f, kTimeName, c + "/time", path);
  const std::int32_t no_pair = -1;
  const double no_force = std::numeric_limits<double>::quiet_NaN();
  const std::int8_t no_flag = -1;
  pairs = create_series(f, c + "/value", H5T_STD_I32LE, {0, 2}, 1, path, &no_pair);
  normal_force = create_series(f, c + "/normal_force", H5T_IEEE_F64LE, {0}, 1, path, &no_force);
  // Discs: the force along t = z x n, one value per contact; spheres: the vector, three.
  tangential_force =
      create_series(f, c + "/tangential_force", H5T_IEEE_F64LE,
                    layout.dimension == 3 ? std::vector<hsize_t>{0, 3} : std::vector<hsize_t>{0}, 1,
                    path, &no_force);
  sliding = create_series(f, c + "/sliding", H5T_STD_I8LE, {0}, 1, path, &no_flag);
  write_unit(pairs->ds.get(), pairs->name, kNumber, path);
  write_unit(normal_force->ds.get(), normal_force->name, kForce, path);
  write_unit(tangential_force->ds.get(), tangential_force->name, kForce, path);
  write_unit(sliding->ds.get(), sliding->name, kNumber, path);
}

H5mdWriter::H5mdWriter(const fs::path& path, const TrajectoryLayout& layout)
    : impl_(std::make_unique<Impl>()) {
  check_layout(path, layout);
  Impl& m = *impl_;
  m.path = path;
  m.layout = layout;
  for (double d : layout.diameter) m.max_diameter = std::max(m.max_diameter, d);
  {
    ErrorPrintGuard quiet;
    const Handle fapl = latest_format(path);
    m.file = checked(H5Fcreate(path.string().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()),
                     H5Fclose, path, "/", "cannot create file");
  }
  write_h5md_header(m.file.get(), path, layout);
  m.create_suspension();
  m.create_observables();
  if (layout.write_contacts) m.create_contacts();
  check(H5Fflush(m.file.get(), H5F_SCOPE_LOCAL), path, "/", "cannot flush file");
}
H5mdWriter::H5mdWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

H5mdWriter H5mdWriter::resume(const fs::path& path, const TrajectoryLayout& layout,
                              long keep_frames) {
  auto m = std::make_unique<Impl>();
  m->path = path;
  m->layout = layout;
  for (double d : layout.diameter) m->max_diameter = std::max(m->max_diameter, d);
  {
    ErrorPrintGuard quiet;
    // A run killed while in single-writer/multiple-reader mode leaves the file marked as open
    // for writing; the resumed run is its one writer again, so it clears the mark (what the
    // HDF5 tool h5clear -s does, through the same file-access property).
    const Handle fapl = latest_format(path);
    hbool_t clear = true;
    H5Pset(fapl.get(), "clear_status_flags", &clear);
    m->file = checked(H5Fopen(path.string().c_str(), H5F_ACC_RDWR, fapl.get()), H5Fclose, path, "/",
                      "cannot reopen the trajectory to resume it");
  }
  const hid_t f = m->file.get();
  const auto rows = static_cast<hsize_t>(keep_frames);
  const hsize_t n = layout.n_particles;
  const auto dim = static_cast<hsize_t>(layout.dimension);
  const auto value = [&](const std::string& full, std::vector<hsize_t> inner, bool ragged = false) {
    return open_series(f, full, std::move(inner), rows, path, ragged);
  };
  // Hard links: cutting position's step and time cuts every element's.
  m->step = value(kStep, {});
  m->time = value(kTimeName, {});
  m->position = value(susp("position/value"), {n, dim});
  m->edges = value(susp("box/edges/value"), {dim, dim});
  if (layout.write_velocity) {
    m->velocity = value(susp("velocity/value"), {n, dim});
    m->angular_velocity = value(susp("angular_velocity/value"),
                                dim == 3 ? std::vector<hsize_t>{n, 3} : std::vector<hsize_t>{n});
  }
  if (H5Lexists(f, susp("image").c_str(), H5P_DEFAULT) > 0)
    m->image = value(susp("image/value"), {n, dim});
  if (H5Lexists(f, susp("unwrapped_position").c_str(), H5P_DEFAULT) > 0)
    m->unwrapped = value(susp("unwrapped_position/value"), {n, dim});
  for (const auto& name : layout.observables)
    m->observables.push_back(value("/observables/" + name + "/value", {}));
  if (layout.write_contacts) {
    const std::string c = kContacts;
    m->pairs = value(c + "/value", {0, 2}, true);
    m->normal_force = value(c + "/normal_force", {0}, true);
    m->tangential_force =
        value(c + "/tangential_force",
              dim == 3 ? std::vector<hsize_t>{0, 3} : std::vector<hsize_t>{0}, true);
    m->sliding = value(c + "/sliding", {0}, true);
  }
  m->frames = keep_frames;
  check(H5Fflush(f, H5F_SCOPE_LOCAL), path, "/", "cannot flush file");
  if (keep_frames > 0) m->start_swmr();  // cut back first: SWMR cannot shrink a dataset
  return H5mdWriter(std::move(m));
}

H5mdWriter::~H5mdWriter() = default;
H5mdWriter::H5mdWriter(H5mdWriter&&) noexcept = default;
H5mdWriter& H5mdWriter::operator=(H5mdWriter&&) noexcept = default;

// Everything about a frame is checked before its first write, so a bad frame leaves the file
// consistent.
void H5mdWriter::Impl::check_frame(const FrameData& frame, bool want_images,
                                   bool want_unwrapped) const {
  const std::size_t n = layout.n_particles;
  const auto check_size = [&](std::size_t got, const std::string& name) {
    if (got != n) {
      fail(path, name,
           fmt::format("frame {} (step {}) has {} entries, expected {}", frames, frame.step, got,
                       n));
    }
  };
  const bool spheres = layout.dimension == 3;
  if (spheres ? frame.position3 == nullptr : frame.position == nullptr)
    fail(path, susp("position"), "frame without positions");
  check_size(spheres ? frame.position3->size() : frame.position->size(), susp("position"));
  if (layout.write_velocity) {
    if (spheres ? frame.velocity6 == nullptr : frame.velocity == nullptr)
      fail(path, susp("velocity"), "frame without velocities");
    check_size(spheres ? frame.velocity6->size() : frame.velocity->size(), susp("velocity"));
  }
  if (want_images &&
      (spheres ? frame.image3 == nullptr : frame.image == nullptr && frame.unwrapped == nullptr))
    fail(path, susp("image"), "images were written at frame 0 but are missing now");
  if (frame.image != nullptr) check_size(frame.image->size(), susp("image"));
  if (frame.image3 != nullptr) check_size(frame.image3->size(), susp("image"));
  if (spheres && !(frame.lz > 0.0))
    fail(path, susp("box/edges"), fmt::format("invalid box lz = {}", frame.lz));
  if (want_unwrapped) {
    if (spheres ? frame.unwrapped3 == nullptr : frame.unwrapped == nullptr) {
      fail(path, susp("unwrapped_position"),
           "unwrapped positions were written at frame 0 but are missing now");
    }
    check_size(spheres ? frame.unwrapped3->size() : frame.unwrapped->size(),
               susp("unwrapped_position"));
  }
  if (frame.observables.size() != layout.observables.size()) {
    fail(path, "/observables",
         fmt::format("frame has {} observable values, layout names {}", frame.observables.size(),
                     layout.observables.size()));
  }
  if (layout.write_contacts) {
    const ContactNetwork* c = frame.contacts;
    if (c == nullptr) fail(path, kContacts, "frame without its contact network");
    const std::size_t k = c->pairs.size();
    if (c->components != (spheres ? 3 : 1))
      fail(path, kContacts,
           fmt::format("{} tangential force components per contact in a {}D file", c->components,
                       layout.dimension));
    const std::size_t width = spheres ? 3 : 1;
    if (c->normal_force.size() != k || c->tangential_force.size() != width * k ||
        c->sliding.size() != k)
      fail(path, kContacts, "contact arrays of different lengths");
    for (const auto& pr : c->pairs)
      for (int i : pr)
        if (i < 0 || static_cast<std::size_t>(i) >= n)
          fail(path, kContacts, fmt::format("particle index {} out of [0, {})", i, n));
  }
  if (!(frame.lx > 0.0) || (layout.lees_edwards && !(frame.ly > 0.0)) || !std::isfinite(frame.tilt))
    fail(path, susp("box/edges"),
         fmt::format("invalid box lx = {}, ly = {}, tilt = {}", frame.lx, frame.ly, frame.tilt));
}

void H5mdWriter::Impl::append_images(const FrameData& frame, double tilt, double ly) {
  const std::size_t n = layout.n_particles;
  const double lx = frame.lx;
  if (layout.dimension == 3) return append_sphere_images(frame);
  const std::vector<Vec2>& pos = *frame.position;
  // position + image . edges is continuous in time (the convention of LAMMPS and GSD): the
  // engine's counts of the images crossed, re-expressed for the reduced tilt of `edges`
  // (tilt = offset - m lx adds m to the x count of each y image). It equals the unwrapped
  // position in y; in x the two differ by the Lees-Edwards shift gained since each crossing.
  std::vector<std::int32_t> img(2 * n);
  const double m_tilt = layout.lees_edwards ? std::round(frame.tilt / lx) : 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (frame.image != nullptr) {
      const auto [ix, iy] = (*frame.image)[i];
      img[2 * i] = static_cast<std::int32_t>(ix + static_cast<int>(m_tilt) * iy);
      img[2 * i + 1] = static_cast<std::int32_t>(iy);
      continue;
    }
    const std::vector<Vec2>& u = *frame.unwrapped;
    const double iy = layout.lees_edwards ? std::round((u[i].y() - pos[i].y()) / ly) : 0.0;
    img[2 * i] = static_cast<std::int32_t>(std::round((u[i].x() - pos[i].x() - iy * tilt) / lx));
    img[2 * i + 1] = static_cast<std::int32_t>(iy);
  }
  image->append(H5T_NATIVE_INT32, img.data(), path);
  if (!unwrapped) return;
  const std::vector<Vec2>& u = *frame.unwrapped;
  std::vector<double> buf(2 * n);
  for (std::size_t i = 0; i < n; ++i) buf[2 * i] = u[i].x(), buf[2 * i + 1] = u[i].y();
  unwrapped->append(H5T_NATIVE_DOUBLE, buf.data(), path);
}

// The images of spheres: x and y as for discs (the counts of the images crossed, re-expressed
// for the reduced tilt), z as crossed.
void H5mdWriter::Impl::append_sphere_images(const FrameData& frame) {
  const std::size_t n = layout.n_particles;
  std::vector<std::int32_t> img(3 * n);
  const double m_tilt = layout.lees_edwards ? std::round(frame.tilt / frame.lx) : 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto [ix, iy, iz] = (*frame.image3)[i];
    img[3 * i] = static_cast<std::int32_t>(ix + static_cast<int>(m_tilt) * iy);
    img[3 * i + 1] = static_cast<std::int32_t>(iy);
    img[3 * i + 2] = static_cast<std::int32_t>(iz);
  }
  image->append(H5T_NATIVE_INT32, img.data(), path);
  if (!unwrapped) return;
  std::vector<double> buf(3 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      buf[3 * i + static_cast<std::size_t>(c)] = (*frame.unwrapped3)[i](c);
  unwrapped->append(H5T_NATIVE_DOUBLE, buf.data(), path);
}

void H5mdWriter::Impl::append_velocity(const FrameData& frame) {
  const std::size_t n = layout.n_particles;
  if (layout.dimension == 3) {
    std::vector<double> u(3 * n), omega(3 * n);
    for (std::size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        u[3 * i + c] = (*frame.velocity6)[i](c);
        omega[3 * i + c] = (*frame.velocity6)[i](3 + c);
      }
    velocity.append(H5T_NATIVE_DOUBLE, u.data(), path);
    angular_velocity.append(H5T_NATIVE_DOUBLE, omega.data(), path);
    return;
  }
  std::vector<double> buf(2 * n);
  const auto& v = *frame.velocity;
  std::vector<double> omega(n);
  for (std::size_t i = 0; i < n; ++i) {
    buf[2 * i] = v[i].x();
    buf[2 * i + 1] = v[i].y();
    omega[i] = v[i].z();
  }
  velocity.append(H5T_NATIVE_DOUBLE, buf.data(), path);
  angular_velocity.append(H5T_NATIVE_DOUBLE, omega.data(), path);
}

void H5mdWriter::Impl::append_contacts(const ContactNetwork& c) {
  const hsize_t k = c.pairs.size();
  std::vector<std::int32_t> ij(2 * k);
  std::vector<std::int8_t> flag(k);
  for (hsize_t q = 0; q < k; ++q) {
    ij[2 * q] = c.pairs[q][0];
    ij[2 * q + 1] = c.pairs[q][1];
    flag[q] = c.sliding[q] != 0 ? 1 : 0;
  }
  pairs->append(H5T_NATIVE_INT32, ij.data(), path, k);
  normal_force->append(H5T_NATIVE_DOUBLE, c.normal_force.data(), path, k);
  tangential_force->append(H5T_NATIVE_DOUBLE, c.tangential_force.data(), path, k);
  sliding->append(H5T_NATIVE_INT8, flag.data(), path, k);
}

void H5mdWriter::write_frame(const FrameData& frame) {
  if (!impl_) throw std::logic_error("H5mdWriter: write_frame on a moved-from writer");
  Impl& m = *impl_;
  if (m.frames_closed) throw std::logic_error("H5mdWriter: write_frame after write_table");
  const std::size_t n = m.layout.n_particles;
  const bool want_images = m.frames == 0 ? frame.image != nullptr || frame.unwrapped != nullptr ||
                                               frame.image3 != nullptr
                                         : m.image.has_value();
  const bool want_unwrapped = m.frames == 0
                                  ? frame.unwrapped != nullptr || frame.unwrapped3 != nullptr
                                  : m.unwrapped.has_value();
  m.check_frame(frame, want_images, want_unwrapped);
  if (m.frames == 0 && want_images) m.create_images(want_unwrapped);

  const auto dim = static_cast<std::size_t>(m.layout.dimension);
  std::vector<double> buf(dim * n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < dim; ++c)
      buf[dim * i + c] = dim == 3 ? (*frame.position3)[i](static_cast<Eigen::Index>(c))
                                  : (*frame.position)[i](static_cast<Eigen::Index>(c));
  const double lx = frame.lx;
  const double tilt = m.layout.lees_edwards ? reduced_tilt(frame.tilt, lx) : 0.0;
  double ly = frame.ly;
  if (!m.layout.lees_edwards) {
    // Placeholder: tall enough that a tool taking y as periodic anyway finds no false contact.
    double lo = buf[1], hi = buf[1];
    for (std::size_t i = 0; i < n; ++i)
      lo = std::min(lo, buf[dim * i + 1]), hi = std::max(hi, buf[dim * i + 1]);
    ly = hi - lo + 2.0 * m.max_diameter;
  }

  const std::int64_t st64 = frame.step;
  m.step.append(H5T_NATIVE_INT64, &st64, m.path);
  m.time.append(H5T_NATIVE_DOUBLE, &frame.time, m.path);
  // Rows: the edge vectors (lx, 0) and (tilt, ly); of spheres (lx, 0, 0), (tilt, ly, 0) and
  // (0, 0, lz).
  const double edges2[4] = {lx, 0.0, tilt, ly};
  const double edges3[9] = {lx, 0.0, 0.0, tilt, ly, 0.0, 0.0, 0.0, frame.lz};
  m.edges.append(H5T_NATIVE_DOUBLE, dim == 3 ? edges3 : edges2, m.path);
  m.position.append(H5T_NATIVE_DOUBLE, buf.data(), m.path);
  if (m.image) m.append_images(frame, tilt, ly);
  if (m.layout.write_velocity) m.append_velocity(frame);
  for (std::size_t k = 0; k < m.observables.size(); ++k)
    m.observables[k].append(H5T_NATIVE_DOUBLE, &frame.observables[k], m.path);
  if (m.layout.write_contacts) m.append_contacts(*frame.contacts);
  ++m.frames;
  m.start_swmr();  // every dataset exists once the first frame is written
}

void H5mdWriter::write_table(const std::string& name, const std::vector<std::string>& columns,
                             const std::vector<std::string>& units, const Eigen::MatrixXd& values) {
  if (!impl_) throw std::logic_error("H5mdWriter: write_table on a moved-from writer");
  Impl& m = *impl_;
  m.leave_swmr();
  check_name(name, m.path, "table");
  const std::string group_name = "/observables/" + name;
  if (columns.size() != static_cast<std::size_t>(values.cols()) || units.size() != columns.size()) {
    fail(m.path, group_name,
         fmt::format("{} column names and {} units for {} columns", columns.size(), units.size(),
                     values.cols()));
  }
  for (const auto& c : columns) check_name(c, m.path, "column");
  // Replaced, not refused: a run resumed from a checkpoint taken before its end writes its
  // tables again over those a killed attempt had written.
  if (H5Lexists(m.file.get(), group_name.c_str(), H5P_DEFAULT) > 0) {
    check(H5Ldelete(m.file.get(), group_name.c_str(), H5P_DEFAULT), m.path, group_name,
          "cannot replace the table");
  }
  Handle group = create_group(m.file.get(), group_name, m.path);
  for (std::size_t c = 0; c < columns.size(); ++c) {
    const Eigen::VectorXd col = values.col(static_cast<Eigen::Index>(c));
    write_fixed_dataset(m.file.get(), group_name + "/" + columns[c], H5T_IEEE_F64LE,
                        H5T_NATIVE_DOUBLE, {static_cast<hsize_t>(values.rows())}, col.data(),
                        units[c], m.path);
  }
}

void H5mdWriter::flush() {
  if (!impl_) throw std::logic_error("H5mdWriter: flush on a moved-from writer");
  check(H5Fflush(impl_->file.get(), H5F_SCOPE_LOCAL), impl_->path, "/", "cannot flush file");
}

long H5mdWriter::frames_written() const {
  return impl_ ? impl_->frames : 0;
}

// ---------------------------------------------------------------------------------------
// Reader

namespace {

hsize_t frame_index(const Reader& r, const std::string& group, long frame) {
  const long frames = count_frames(r, group);
  if (frame < -1 || frame >= frames || (frame == -1 && frames == 0)) {
    fail(r.path(), group + "/position/value",
         fmt::format("frame {} out of range ({} frames)", frame, frames));
  }
  return static_cast<hsize_t>(frame == -1 ? frames - 1 : frame);
}

// Positions or velocities of row idx: (N, D) with D = 2, or 3 of which x and y are kept.
std::vector<Vec2> read_vectors(const Reader& r, const std::string& name, hsize_t idx,
                               std::optional<hsize_t> n) {
  std::vector<hsize_t> inner;
  const auto flat = r.read_rows<double>(name, H5T_NATIVE_DOUBLE, idx, 1, &inner);
  if (inner.size() != 2 || (inner[1] != 2 && inner[1] != 3) || (n && inner[0] != *n)) {
    fail(r.path(), name,
         fmt::format("unexpected shape (frames, {}), expected (frames, {}, 2 or 3)",
                     fmt::join(inner, ", "), n ? std::to_string(*n) : "N"));
  }
  return to_vec2(flat, inner[1]);
}

}  // namespace

long count_h5md_frames(const fs::path& file) {
  const Reader r(file);
  return count_frames(r, particle_group(r));
}

namespace {

// The box of frame idx: y periodic or not, and the edges (cuboid or triclinic with edge vectors
// (lx, 0) and (xy, ly), time-dependent or not) where the file has them.
void read_box(const Reader& r, const std::string& g, hsize_t idx, H5mdFrame& out) {
  const fs::path& file = r.path();
  const std::string box = g + "/box";
  if (!r.exists(box)) fail(file, box, "object not found");
  const auto boundary = r.string_attr(box, "boundary");
  if (boundary.size() < 2) fail(file, box + "@boundary", "expected 2 or 3 entries");
  out.periodic_y = boundary[1] == "periodic";
  const std::string edges_name = box + "/edges";
  if (!r.exists(edges_name)) return;
  std::vector<hsize_t> inner;
  std::vector<double> e;
  std::string where = edges_name;
  if (r.is_group(edges_name)) {  // time-dependent
    where += "/value";
    e = r.read_rows<double>(where, H5T_NATIVE_DOUBLE, idx, 1, &inner);
  } else {
    e = r.read_all<double>(where, H5T_NATIVE_DOUBLE, &inner);
    inner = r.dims(where);
  }
  const hsize_t dim = inner.empty() ? 0 : inner[0];
  if (dim != 2 && dim != 3) fail(file, where, "expected the edges of a 2D or 3D box");
  if (inner.size() == 1) {  // cuboid: the space diagonal
    out.lx = e[0];
    out.ly = e[1];
  } else if (inner.size() == 2 && inner[1] == dim) {  // triclinic: edge vectors as rows
    out.lx = e[0];
    out.tilt = e[dim];
    out.ly = e[dim + 1];
    if (e[1] != 0.0)
      fail(file, where,
           fmt::format("the first edge vector ({}, {}) is not along x: only boxes with edges "
                       "(lx, 0) and (xy, ly) (LAMMPS, GSD) can be read",
                       e[0], e[1]));
  } else {
    fail(file, where, fmt::format("unexpected shape ({})", fmt::join(inner, ", ")));
  }
}

// Velocities (x, y) and angular velocities (z) of frame idx, where the file has either.
void read_velocities(const Reader& r, const std::string& g, hsize_t idx, hsize_t n,
                     H5mdFrame& out) {
  const std::string vel_name = g + "/velocity/value";
  const std::string omega_name = g + "/angular_velocity/value";
  const bool has_vel = r.exists(vel_name);
  const bool has_omega = r.exists(omega_name);
  if (!has_vel && !has_omega) return;
  out.velocity.assign(n, Vec3::Zero());
  if (has_vel) {
    const auto v = read_vectors(r, vel_name, idx, n);
    for (std::size_t i = 0; i < n; ++i) out.velocity[i].head<2>() = v[i];
  }
  if (has_omega) {
    std::vector<hsize_t> inner;
    const auto w = r.read_rows<double>(omega_name, H5T_NATIVE_DOUBLE, idx, 1, &inner);
    // Discs: omega (a scalar about z); spheres: the vector, of which z is kept.
    const std::size_t width = out.dimension == 3 ? 3 : 1;
    expect_shape(r, omega_name, inner,
                 width == 3 ? std::vector<hsize_t>{n, 3} : std::vector<hsize_t>{n});
    for (std::size_t i = 0; i < n; ++i) out.velocity[i].z() = w[width * i + width - 1];
  }
}

// One value per particle (diameter, species, motion), time-independent or not. Optional, so
// that files from other H5MD writers still load.
template <class T>
void read_per_particle(const Reader& r, const std::string& g, const char* rel, hid_t mem_type,
                       hsize_t idx, hsize_t n, std::vector<T>& dest) {
  std::string name = g + "/" + rel;
  if (!r.exists(name)) return;
  std::vector<hsize_t> inner;
  if (r.is_group(name)) {
    name += "/value";
    dest = r.read_rows<T>(name, mem_type, idx, 1, &inner);
  } else {
    dest = r.read_all<T>(name, mem_type, &inner);
    inner.clear();
  }
  expect_shape(r, name, inner, {});
  if (dest.size() != n)
    fail(r.path(), name, fmt::format("{} entries, position has {}", dest.size(), n));
}

}  // namespace

H5mdFrame read_h5md_frame(const fs::path& file, long frame) {
  const Reader r(file);
  const std::string g = particle_group(r);
  const hsize_t idx = frame_index(r, g, frame);

  H5mdFrame out;
  out.position = read_vectors(r, g + "/position/value", idx, std::nullopt);
  const hsize_t n = out.position.size();
  out.dimension = static_cast<int>(r.dims(g + "/position/value").back());
  out.step =
      static_cast<long>(axis_value<std::int64_t>(r, g + "/position/step", H5T_NATIVE_INT64, idx));
  if (r.exists(g + "/position/time"))
    out.time = axis_value<double>(r, g + "/position/time", H5T_NATIVE_DOUBLE, idx);
  read_box(r, g, idx, out);
  const std::string unwrapped_name = g + "/unwrapped_position/value";
  const std::string image_name = g + "/image/value";
  if (r.exists(unwrapped_name)) {
    out.unwrapped = read_vectors(r, unwrapped_name, idx, n);
  } else if (r.exists(image_name) && !out.periodic_y) {
    // Without Lees-Edwards the unwrapped position is position + image . edges (not stored).
    out.unwrapped = read_vectors(r, image_name, idx, n);
    for (std::size_t i = 0; i < n; ++i)
      out.unwrapped[i] = out.position[i] + Vec2(out.unwrapped[i].x() * out.lx, 0.0);
  }
  read_velocities(r, g, idx, n, out);
  read_per_particle(r, g, "diameter", H5T_NATIVE_DOUBLE, idx, n, out.diameter);
  read_per_particle(r, g, "species", H5T_NATIVE_INT, idx, n, out.species);
  read_per_particle(r, g, "motion", H5T_NATIVE_INT, idx, n, out.motion);
  return out;
}

ContactNetwork read_h5md_contacts(const fs::path& file, long frame) {
  const Reader r(file);
  const std::string g = particle_group(r);
  const hsize_t idx = frame_index(r, g, frame);
  ContactNetwork c;
  const std::string base = kContacts;
  if (!r.exists(base + "/value")) return c;
  std::vector<hsize_t> inner;
  const auto ij = r.read_rows<std::int32_t>(base + "/value", H5T_NATIVE_INT32, idx, 1, &inner);
  if (inner.size() != 2 || inner[1] != 2) fail(file, base + "/value", "expected (frames, M, 2)");
  const auto fn = r.read_rows<double>(base + "/normal_force", H5T_NATIVE_DOUBLE, idx, 1);
  std::vector<hsize_t> ft_inner;
  const auto ft =
      r.read_rows<double>(base + "/tangential_force", H5T_NATIVE_DOUBLE, idx, 1, &ft_inner);
  // (frames, M) for discs, (frames, M, 3) for spheres.
  if (ft_inner.size() == 2 && ft_inner[1] == 3)
    c.components = 3;
  else if (ft_inner.size() != 1)
    fail(file, base + "/tangential_force", "expected (frames, M) or (frames, M, 3)");
  const auto sl = r.read_rows<std::int8_t>(base + "/sliding", H5T_NATIVE_INT8, idx, 1);
  const auto width = static_cast<std::size_t>(c.components);
  if (fn.size() != inner[0] || ft.size() != width * inner[0] || sl.size() != inner[0])
    fail(file, base, "per-contact datasets of different widths");
  for (std::size_t q = 0; q < inner[0]; ++q) {
    if (ij[2 * q] < 0 || ij[2 * q + 1] < 0) continue;  // the fill value: no contact
    c.pairs.push_back({ij[2 * q], ij[2 * q + 1]});
    c.normal_force.push_back(fn[q]);
    c.tangential_force.insert(c.tangential_force.end(), ft.begin() + width * q,
                              ft.begin() + width * (q + 1));
    c.sliding.push_back(sl[q]);
  }
  return c;
}

bool has_h5md_observable(const fs::path& file, const std::string& name) {
  return !name.empty() && Reader(file).exists("/observables/" + name);
}

ObservableSeries read_h5md_observable(const fs::path& file, const std::string& name) {
  const Reader r(file);
  const std::string base = "/observables/" + name;
  if (name.empty() || !r.exists(base)) fail(file, base, "observable not found");
  std::vector<hsize_t> inner;
  const auto steps = r.read_all<std::int64_t>(base + "/step", H5T_NATIVE_INT64, &inner);
  expect_shape(r, base + "/step", inner, {});
  ObservableSeries s;
  s.time = r.read_all<double>(base + "/time", H5T_NATIVE_DOUBLE, &inner);
  expect_shape(r, base + "/time", inner, {});
  s.value = r.read_all<double>(base + "/value", H5T_NATIVE_DOUBLE, &inner);
  expect_shape(r, base + "/value", inner, {});
  const std::size_t len = std::min({steps.size(), s.time.size(), s.value.size()});
  s.step.assign(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(len));
  s.time.resize(len);
  s.value.resize(len);
  return s;
}

}  // namespace sheardiff
