#include "sheardiff/io/h5md.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <hdf5.h>

#include <algorithm>
#include <cstdint>
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

Handle string_type(const fs::path& file, std::string_view object) {
  Handle t = checked(H5Tcopy(H5T_C_S1), H5Tclose, file, object, "cannot create string type");
  check(H5Tset_size(t.get(), H5T_VARIABLE), file, object, "cannot create string type");
  check(H5Tset_cset(t.get(), H5T_CSET_UTF8), file, object, "cannot create string type");
  return t;
}

// Variable-length strings keep large values (the config text) out of the 64 kB object header.
void write_string_attr(hid_t obj, const std::string& obj_name, const char* attr,
                       const std::vector<std::string>& values, bool scalar, const fs::path& file) {
  const std::string where = obj_name + "@" + attr;
  Handle type = string_type(file, where);
  Handle space =
      scalar ? checked(H5Screate(H5S_SCALAR), H5Sclose, file, where, "cannot create dataspace")
             : simple_space({values.size()}, nullptr, file, where);
  Handle a = checked(H5Acreate2(obj, attr, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
                     H5Aclose, file, where, "cannot create attribute");
  std::vector<const char*> ptrs;
  ptrs.reserve(values.size());
  for (const auto& v : values) ptrs.push_back(v.c_str());
  check(H5Awrite(a.get(), type.get(), ptrs.data()), file, where, "cannot write attribute");
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

template <class T>
void write_fixed_dataset(hid_t loc, const std::string& full, hid_t file_type, hid_t mem_type,
                         const std::vector<hsize_t>& dims, const T* data, const fs::path& file) {
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
}

// A dataset growing by one row per frame along an unlimited first dimension.
struct Series {
  Handle ds;
  std::string name;
  std::vector<hsize_t> inner;  // shape of one row
  hsize_t rows = 0;

  void append(hid_t mem_type, const void* data, const fs::path& file) {
    std::vector<hsize_t> dims{rows + 1};
    dims.insert(dims.end(), inner.begin(), inner.end());
    check(H5Dset_extent(ds.get(), dims.data()), file, name, "cannot extend dataset");
    Handle fspace = checked(H5Dget_space(ds.get()), H5Sclose, file, name, "cannot get dataspace");
    std::vector<hsize_t> start(dims.size(), 0);
    start[0] = rows;
    std::vector<hsize_t> count = dims;
    count[0] = 1;
    check(H5Sselect_hyperslab(fspace.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(),
                              nullptr),
          file, name, "cannot select row");
    Handle mspace = simple_space(count, nullptr, file, name);
    check(H5Dwrite(ds.get(), mem_type, mspace.get(), fspace.get(), H5P_DEFAULT, data), file, name,
          "cannot write row");
    ++rows;
  }
};

Series create_series(hid_t loc, const std::string& full, hid_t file_type,
                     std::vector<hsize_t> inner, hsize_t chunk_rows, const fs::path& file) {
  std::vector<hsize_t> dims{0};
  dims.insert(dims.end(), inner.begin(), inner.end());
  std::vector<hsize_t> maxdims = dims;
  maxdims[0] = H5S_UNLIMITED;
  std::vector<hsize_t> chunk = dims;
  chunk[0] = chunk_rows;
  Handle space = simple_space(dims, &maxdims, file, full);
  Handle dcpl =
      checked(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, file, full, "cannot create property list");
  check(H5Pset_chunk(dcpl.get(), static_cast<int>(chunk.size()), chunk.data()), file, full,
        "cannot set chunking");
  Series s;
  s.ds = checked(
      H5Dcreate2(loc, full.c_str(), file_type, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
      H5Dclose, file, full, "cannot create dataset");
  s.name = full;
  s.inner = std::move(inner);
  return s;
}

// Opens an existing series and cuts it back to `rows` rows.
Series open_series(hid_t loc, const std::string& full, std::vector<hsize_t> inner, hsize_t rows,
                   const fs::path& file) {
  Series s;
  s.ds = checked(H5Dopen2(loc, full.c_str(), H5P_DEFAULT), H5Dclose, file, full,
                 "cannot open dataset");
  s.name = full;
  s.inner = std::move(inner);
  Handle space = checked(H5Dget_space(s.ds.get()), H5Sclose, file, full, "cannot get dataspace");
  hsize_t have = 0;
  if (H5Sget_simple_extent_ndims(space.get()) < 1) fail(file, full, "expected rank >= 1");
  std::vector<hsize_t> dims(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space.get())));
  H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  have = dims[0];
  if (have < rows)
    fail(file, full, fmt::format("holds {} rows, the checkpoint needs {}", have, rows));
  dims[0] = rows;
  check(H5Dset_extent(s.ds.get(), dims.data()), file, full, "cannot truncate dataset");
  s.rows = rows;
  return s;
}

// H5MD time-dependent element: group with step, time and value.
struct TimeElement {
  Handle group;
  Series step, time, value;

  void append(long st, double t, hid_t mem_type, const void* data, const fs::path& file) {
    const std::int64_t st64 = st;
    step.append(H5T_NATIVE_INT64, &st64, file);
    time.append(H5T_NATIVE_DOUBLE, &t, file);
    value.append(mem_type, data, file);
  }
};

TimeElement create_element(hid_t loc, const std::string& full, std::vector<hsize_t> inner,
                           hsize_t chunk_rows, const fs::path& file) {
  TimeElement e;
  e.group = create_group(loc, full, file);
  e.step = create_series(loc, full + "/step", H5T_STD_I64LE, {}, kScalarChunk, file);
  e.time = create_series(loc, full + "/time", H5T_IEEE_F64LE, {}, kScalarChunk, file);
  e.value = create_series(loc, full + "/value", H5T_IEEE_F64LE, std::move(inner), chunk_rows, file);
  return e;
}

void check_name(const std::string& name, const fs::path& file, std::string_view what) {
  if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..") {
    fail(file, "/observables/" + name, fmt::format("invalid {} name", what));
  }
}

// Read-only access with existence checks, so missing objects give a clean message
// instead of an HDF5 error stack.
class Reader {
 public:
  explicit Reader(const fs::path& path) : path_(path) {
    std::error_code ec;
    if (!fs::exists(path_, ec)) fail(path_, "/", "file does not exist");
    ErrorPrintGuard quiet;
    file_ = checked(H5Fopen(path_.string().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, path_,
                    "/", "cannot open file as HDF5");
  }

  const fs::path& path() const { return path_; }

  // H5Lexists fails (not false) on a missing intermediate group, so walk the components.
  bool exists(const std::string& name) const {
    std::size_t pos = 0;
    while (pos != std::string::npos) {
      pos = name.find('/', pos + 1);
      const std::string prefix = name.substr(0, pos);
      if (H5Lexists(file_.get(), prefix.c_str(), H5P_DEFAULT) <= 0) return false;
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
    return read_rows<T>(name, mem_type, 0, rows(name), inner);
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

  fs::path path_;
  Handle file_;
};

std::string susp(const char* rel) {
  return std::string(kSuspension) + "/" + rel;
}

long count_frames(const Reader& r) {
  hsize_t n = r.rows(susp("position/value"));
  n = std::min(n, r.rows(susp("position/step")));
  n = std::min(n, r.rows(susp("position/time")));
  const std::string edges = susp("box/edges/value");
  if (r.exists(edges)) n = std::min(n, r.rows(edges));
  return static_cast<long>(n);
}

std::vector<Vec2> to_vec2(const std::vector<double>& flat) {
  std::vector<Vec2> out(flat.size() / 2);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = Vec2(flat[2 * i], flat[2 * i + 1]);
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

}  // namespace

// ---------------------------------------------------------------------------------------
// Writer

struct H5mdWriter::Impl {
  fs::path path;
  TrajectoryLayout layout;
  Handle file;  // declared first so it is closed after all objects inside it
  TimeElement edges, position, velocity, angular_velocity;
  std::optional<TimeElement> unwrapped;
  std::vector<TimeElement> observables;
  long frames = 0;

  ~Impl() {
    if (file.valid()) H5Fflush(file.get(), H5F_SCOPE_LOCAL);
  }
};

H5mdWriter::H5mdWriter(const fs::path& path, const TrajectoryLayout& layout)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  m.layout = layout;
  const std::size_t n = layout.n_particles;
  if (n == 0) fail(path, kSuspension, "layout has no particles");
  if (layout.species.size() != n || layout.diameter.size() != n || layout.motion.size() != n) {
    fail(path, kSuspension,
         fmt::format("layout arrays sizes species={} diameter={} motion={} != n_particles={}",
                     layout.species.size(), layout.diameter.size(), layout.motion.size(), n));
  }
  for (std::size_t i = 0; i < layout.observables.size(); ++i) {
    check_name(layout.observables[i], path, "observable");
    for (std::size_t j = 0; j < i; ++j) {
      if (layout.observables[j] == layout.observables[i]) {
        fail(path, "/observables/" + layout.observables[i], "duplicate observable name");
      }
    }
  }

  {
    ErrorPrintGuard quiet;
    m.file = checked(H5Fcreate(path.string().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
                     H5Fclose, path, "/", "cannot create file");
  }
  const hid_t f = m.file.get();

  {
    Handle h5md = create_group(f, "/h5md", path);
    write_int_attr(h5md.get(), "/h5md", "version", {1, 1}, false, path);
    Handle author = create_group(f, "/h5md/author", path);
    write_string_attr(author.get(), "/h5md/author", "name", {"sheardiff"}, true, path);
    Handle creator = create_group(f, "/h5md/creator", path);
    write_string_attr(creator.get(), "/h5md/creator", "name", {"sheardiff"}, true, path);
    write_string_attr(creator.get(), "/h5md/creator", "version", {layout.creator_version}, true,
                      path);
  }
  {
    Handle parameters = create_group(f, "/parameters", path);
    write_string_attr(parameters.get(), "/parameters", "config", {layout.config_toml}, true, path);
  }

  Handle particles = create_group(f, "/particles", path);
  Handle suspension = create_group(f, kSuspension, path);
  {
    const std::string box_name = susp("box");
    Handle box = create_group(f, box_name, path);
    write_int_attr(box.get(), box_name, "dimension", {2}, true, path);
    write_string_attr(box.get(), box_name, "boundary",
                      {"periodic", layout.lees_edwards ? "periodic" : "none"}, false, path);
  }
  m.edges = create_element(f, susp("box/edges"), {2}, kScalarChunk, path);
  m.position = create_element(f, susp("position"), {n, 2}, 1, path);
  if (layout.write_velocity) {
    m.velocity = create_element(f, susp("velocity"), {n, 2}, 1, path);
    m.angular_velocity = create_element(f, susp("angular_velocity"), {n}, 1, path);
  }
  write_fixed_dataset(f, susp("species"), H5T_STD_I32LE, H5T_NATIVE_INT, {n}, layout.species.data(),
                      path);
  write_fixed_dataset(f, susp("diameter"), H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {n},
                      layout.diameter.data(), path);
  write_fixed_dataset(f, susp("motion"), H5T_STD_I32LE, H5T_NATIVE_INT, {n}, layout.motion.data(),
                      path);

  Handle obs_group = create_group(f, "/observables", path);
  for (const auto& name : layout.observables) {
    m.observables.push_back(create_element(f, "/observables/" + name, {}, kScalarChunk, path));
  }
  check(H5Fflush(f, H5F_SCOPE_LOCAL), path, "/", "cannot flush file");
}

H5mdWriter::H5mdWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

H5mdWriter H5mdWriter::resume(const fs::path& path, const TrajectoryLayout& layout,
                              long keep_frames) {
  auto m = std::make_unique<Impl>();
  m->path = path;
  m->layout = layout;
  {
    ErrorPrintGuard quiet;
    m->file = checked(H5Fopen(path.string().c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose, path,
                      "/", "cannot reopen the trajectory to resume it");
  }
  const hid_t f = m->file.get();
  const auto rows = static_cast<hsize_t>(keep_frames);
  const hsize_t n = layout.n_particles;
  const auto element = [&](const std::string& full, std::vector<hsize_t> inner) {
    TimeElement e;
    e.group = checked(H5Gopen2(f, full.c_str(), H5P_DEFAULT), H5Gclose, path, full,
                      "cannot open group");
    e.step = open_series(f, full + "/step", {}, rows, path);
    e.time = open_series(f, full + "/time", {}, rows, path);
    e.value = open_series(f, full + "/value", std::move(inner), rows, path);
    return e;
  };
  m->edges = element(susp("box/edges"), {2});
  m->position = element(susp("position"), {n, 2});
  if (layout.write_velocity) {
    m->velocity = element(susp("velocity"), {n, 2});
    m->angular_velocity = element(susp("angular_velocity"), {n});
  }
  if (H5Lexists(f, susp("unwrapped_position").c_str(), H5P_DEFAULT) > 0)
    m->unwrapped = element(susp("unwrapped_position"), {n, 2});
  for (const auto& name : layout.observables) m->observables.push_back(element("/observables/" + name, {}));
  m->frames = keep_frames;
  check(H5Fflush(f, H5F_SCOPE_LOCAL), path, "/", "cannot flush file");
  return H5mdWriter(std::move(m));
}

H5mdWriter::~H5mdWriter() = default;
H5mdWriter::H5mdWriter(H5mdWriter&&) noexcept = default;
H5mdWriter& H5mdWriter::operator=(H5mdWriter&&) noexcept = default;

void H5mdWriter::write_frame(const FrameData& frame) {
  if (!impl_) throw std::logic_error("H5mdWriter: write_frame on a moved-from writer");
  Impl& m = *impl_;
  const std::size_t n = m.layout.n_particles;
  const auto check_size = [&](std::size_t got, const std::string& name) {
    if (got != n) {
      fail(m.path, name,
           fmt::format("frame {} (step {}) has {} entries, expected {}", m.frames, frame.step, got,
                       n));
    }
  };

  // Validate everything before the first write so a bad frame leaves the file consistent.
  if (frame.position == nullptr) fail(m.path, susp("position"), "frame without positions");
  check_size(frame.position->size(), susp("position"));
  if (m.layout.write_velocity) {
    if (frame.velocity == nullptr) fail(m.path, susp("velocity"), "frame without velocities");
    check_size(frame.velocity->size(), susp("velocity"));
  }
  const bool want_unwrapped = m.frames == 0 ? frame.unwrapped != nullptr : m.unwrapped.has_value();
  if (want_unwrapped) {
    if (frame.unwrapped == nullptr) {
      fail(m.path, susp("unwrapped_position"),
           "unwrapped positions were written at frame 0 but are missing now");
    }
    check_size(frame.unwrapped->size(), susp("unwrapped_position"));
  }
  if (frame.observables.size() != m.layout.observables.size()) {
    fail(m.path, "/observables",
         fmt::format("frame has {} observable values, layout names {}", frame.observables.size(),
                     m.layout.observables.size()));
  }

  if (m.frames == 0 && want_unwrapped) {
    m.unwrapped = create_element(m.file.get(), susp("unwrapped_position"), {n, 2}, 1, m.path);
  }

  const double edges[2] = {frame.lx, frame.ly};
  m.edges.append(frame.step, frame.time, H5T_NATIVE_DOUBLE, edges, m.path);

  std::vector<double> buf(2 * n);
  const auto flatten2 = [&](const std::vector<Vec2>& v) {
    for (std::size_t i = 0; i < n; ++i) {
      buf[2 * i] = v[i].x();
      buf[2 * i + 1] = v[i].y();
    }
  };
  flatten2(*frame.position);
  m.position.append(frame.step, frame.time, H5T_NATIVE_DOUBLE, buf.data(), m.path);
  if (m.unwrapped) {
    flatten2(*frame.unwrapped);
    m.unwrapped->append(frame.step, frame.time, H5T_NATIVE_DOUBLE, buf.data(), m.path);
  }
  if (m.layout.write_velocity) {
    const auto& v = *frame.velocity;
    std::vector<double> omega(n);
    for (std::size_t i = 0; i < n; ++i) {
      buf[2 * i] = v[i].x();
      buf[2 * i + 1] = v[i].y();
      omega[i] = v[i].z();
    }
    m.velocity.append(frame.step, frame.time, H5T_NATIVE_DOUBLE, buf.data(), m.path);
    m.angular_velocity.append(frame.step, frame.time, H5T_NATIVE_DOUBLE, omega.data(), m.path);
  }
  for (std::size_t k = 0; k < m.observables.size(); ++k) {
    m.observables[k].append(frame.step, frame.time, H5T_NATIVE_DOUBLE, &frame.observables[k],
                            m.path);
  }
  ++m.frames;
}

void H5mdWriter::write_table(const std::string& name, const std::vector<std::string>& columns,
                             const Eigen::MatrixXd& values) {
  if (!impl_) throw std::logic_error("H5mdWriter: write_table on a moved-from writer");
  Impl& m = *impl_;
  check_name(name, m.path, "table");
  const std::string group_name = "/observables/" + name;
  if (columns.size() != static_cast<std::size_t>(values.cols())) {
    fail(m.path, group_name,
         fmt::format("{} column names for {} columns", columns.size(), values.cols()));
  }
  // Replaced, not refused: a run resumed from a checkpoint taken before its end writes its
  // tables again over those a killed attempt had written.
  if (H5Lexists(m.file.get(), group_name.c_str(), H5P_DEFAULT) > 0) {
    check(H5Ldelete(m.file.get(), group_name.c_str(), H5P_DEFAULT), m.path, group_name,
          "cannot replace the table");
  }
  Handle group = create_group(m.file.get(), group_name, m.path);
  // HDF5 is row-major, Eigen's default column-major.
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const RowMajor rm = values;
  const std::string value_name = group_name + "/value";
  write_fixed_dataset(m.file.get(), value_name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                      {static_cast<hsize_t>(values.rows()), static_cast<hsize_t>(values.cols())},
                      rm.data(), m.path);
  Handle ds = checked(H5Dopen2(m.file.get(), value_name.c_str(), H5P_DEFAULT), H5Dclose, m.path,
                      value_name, "cannot open dataset");
  write_string_attr(ds.get(), value_name, "columns", columns, false, m.path);
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

long count_h5md_frames(const fs::path& file) {
  const Reader r(file);
  return count_frames(r);
}

H5mdFrame read_h5md_frame(const fs::path& file, long frame) {
  const Reader r(file);
  const long frames = count_frames(r);
  const std::string pos_name = susp("position/value");
  if (frame < -1 || frame >= frames || (frame == -1 && frames == 0)) {
    fail(file, pos_name, fmt::format("frame {} out of range ({} frames)", frame, frames));
  }
  const auto idx = static_cast<hsize_t>(frame == -1 ? frames - 1 : frame);

  H5mdFrame out;
  std::vector<hsize_t> inner;
  const auto pos = r.read_rows<double>(pos_name, H5T_NATIVE_DOUBLE, idx, 1, &inner);
  if (inner.size() != 2 || inner[1] != 2) {
    fail(file, pos_name,
         fmt::format("unexpected shape (frames, {}), expected (frames, N, 2)",
                     fmt::join(inner, ", ")));
  }
  const hsize_t n = inner[0];
  out.position = to_vec2(pos);
  out.step = static_cast<long>(
      r.read_rows<std::int64_t>(susp("position/step"), H5T_NATIVE_INT64, idx, 1)[0]);
  out.time = r.read_rows<double>(susp("position/time"), H5T_NATIVE_DOUBLE, idx, 1)[0];

  const std::string edges_name = susp("box/edges");
  if (!r.exists(edges_name)) fail(file, edges_name, "object not found");
  std::vector<double> edges;
  if (r.is_group(edges_name)) {
    edges = r.read_rows<double>(edges_name + "/value", H5T_NATIVE_DOUBLE, idx, 1, &inner);
    expect_shape(r, edges_name + "/value", inner, {2});
  } else {  // H5MD also allows a time-independent box
    edges = r.read_all<double>(edges_name, H5T_NATIVE_DOUBLE, &inner);
    expect_shape(r, edges_name, inner, {});
    if (edges.size() != 2) fail(file, edges_name, "expected 2 edges");
  }
  out.lx = edges[0];
  out.ly = edges[1];

  const std::string unwrapped_name = susp("unwrapped_position/value");
  if (r.exists(unwrapped_name)) {
    out.unwrapped = to_vec2(r.read_rows<double>(unwrapped_name, H5T_NATIVE_DOUBLE, idx, 1, &inner));
    expect_shape(r, unwrapped_name, inner, {n, 2});
  }

  const std::string vel_name = susp("velocity/value");
  const std::string omega_name = susp("angular_velocity/value");
  const bool has_vel = r.exists(vel_name);
  const bool has_omega = r.exists(omega_name);
  if (has_vel || has_omega) {
    out.velocity.assign(n, Vec3::Zero());
    if (has_vel) {
      const auto v = r.read_rows<double>(vel_name, H5T_NATIVE_DOUBLE, idx, 1, &inner);
      expect_shape(r, vel_name, inner, {n, 2});
      for (std::size_t i = 0; i < n; ++i) {
        out.velocity[i].x() = v[2 * i];
        out.velocity[i].y() = v[2 * i + 1];
      }
    }
    if (has_omega) {
      const auto w = r.read_rows<double>(omega_name, H5T_NATIVE_DOUBLE, idx, 1, &inner);
      expect_shape(r, omega_name, inner, {n});
      for (std::size_t i = 0; i < n; ++i) out.velocity[i].z() = w[i];
    }
  }

  // Optional so files from other H5MD writers still load.
  const auto per_particle = [&](const char* rel, hid_t mem_type, auto& dest) {
    const std::string name = susp(rel);
    if (!r.exists(name)) return;
    using T = typename std::decay_t<decltype(dest)>::value_type;
    dest = r.read_all<T>(name, mem_type, &inner);
    expect_shape(r, name, inner, {});
    if (dest.size() != n) {
      fail(file, name, fmt::format("{} entries, position has {}", dest.size(), n));
    }
  };
  per_particle("diameter", H5T_NATIVE_DOUBLE, out.diameter);
  per_particle("species", H5T_NATIVE_INT, out.species);
  per_particle("motion", H5T_NATIVE_INT, out.motion);
  return out;
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
