#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "scratch_dir.hpp"
#include "sheardiff/io/h5md.hpp"

namespace sheardiff {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kN = 5;
constexpr int kFrames = 3;

// Exactly representable values so equality after the round trip is meaningful.
Vec2 pos(int f, std::size_t i) {
  return {0.25 * f + 1.5 * i, -0.125 * f + 0.5 * i};
}
Vec2 unw(int f, std::size_t i) {
  return {10.0 * f + i, 3.0 - 2.0 * i};
}
Vec3 vel(int f, std::size_t i) {
  return {0.5 * f - i, 0.75 * i, -0.0625 * (f + i)};
}
double ly_at(int f) {
  return 8.0 - 0.5 * f;
}
double tilt_at(int f) {
  return 7.0 + f;  // stored reduced into [-3, 3]: 1, 2, -3
}
long step_at(int f) {
  return 100 * f + 7;
}
double time_at(int f) {
  return 0.125 * f;
}
double obs_a(int f) {
  return 1.0 + f;
}
double obs_b(int f) {
  return -2.5 * f;
}

TrajectoryLayout make_layout() {
  TrajectoryLayout l;
  l.n_particles = kN;
  l.species = {0, 1, 0, 1, 1};
  l.diameter = {1.0, 1.4, 1.0, 1.4, 1.4};
  l.motion = {0, 0, 0, 1, 2};
  l.lx = 6;
  l.ly = 8;
  l.lees_edwards = true;
  l.write_velocity = true;
  l.observables = {"stress_xy", "energy"};
  l.creator_version = "0.1.0";
  l.config_toml = "[scene]\nkind = \"shear\"\n";
  return l;
}

void write_test_file(const fs::path& file) {
  H5mdWriter w(file, make_layout());
  for (int f = 0; f < kFrames; ++f) {
    std::vector<Vec2> p(kN), u(kN);
    std::vector<Vec3> v(kN);
    for (std::size_t i = 0; i < kN; ++i) {
      p[i] = pos(f, i);
      u[i] = unw(f, i);
      v[i] = vel(f, i);
    }
    FrameData fd;
    fd.step = step_at(f);
    fd.time = time_at(f);
    fd.lx = 6;
    fd.ly = ly_at(f);
    fd.tilt = tilt_at(f);
    fd.position = &p;
    fd.unwrapped = &u;
    fd.velocity = &v;
    fd.observables = {obs_a(f), obs_b(f)};
    w.write_frame(fd);
  }
  EXPECT_EQ(w.frames_written(), kFrames);
  Eigen::MatrixXd table(2, 3);
  table << 1, 2, 3, 4, 5, 6;
  w.write_table("profile", {"y", "u_x", "phi"}, {"d", "P d eta-1", "1"}, table);
}

void expect_frame(const H5mdFrame& fr, int f) {
  EXPECT_EQ(fr.step, step_at(f));
  EXPECT_EQ(fr.time, time_at(f));
  EXPECT_EQ(fr.lx, 6.0);
  EXPECT_EQ(fr.ly, ly_at(f));
  EXPECT_EQ(fr.tilt, tilt_at(f) - 6.0 * std::round(tilt_at(f) / 6.0));
  EXPECT_TRUE(fr.periodic_y);
  ASSERT_EQ(fr.position.size(), kN);
  ASSERT_EQ(fr.unwrapped.size(), kN);
  ASSERT_EQ(fr.velocity.size(), kN);
  for (std::size_t i = 0; i < kN; ++i) {
    EXPECT_EQ(fr.position[i], pos(f, i)) << "frame " << f << " particle " << i;
    EXPECT_EQ(fr.unwrapped[i], unw(f, i)) << "frame " << f << " particle " << i;
    EXPECT_EQ(fr.velocity[i], vel(f, i)) << "frame " << f << " particle " << i;
  }
  EXPECT_EQ(fr.species, (std::vector<int>{0, 1, 0, 1, 1}));
  EXPECT_EQ(fr.diameter, (std::vector<double>{1.0, 1.4, 1.0, 1.4, 1.4}));
  EXPECT_EQ(fr.motion, (std::vector<int>{0, 0, 0, 1, 2}));
}

TEST(H5md, RoundTripFrames) {
  const ScratchDir dir;
  const fs::path file = dir.path() / "traj.h5";
  write_test_file(file);

  EXPECT_EQ(count_h5md_frames(file), kFrames);
  expect_frame(read_h5md_frame(file, 0), 0);
  expect_frame(read_h5md_frame(file, 1), 1);
  expect_frame(read_h5md_frame(file, 2), 2);
  expect_frame(read_h5md_frame(file, -1), 2);
  expect_frame(read_h5md_frame(file), 2);
  EXPECT_THROW(read_h5md_frame(file, 3), std::runtime_error);
  EXPECT_THROW(read_h5md_frame(file, -2), std::runtime_error);
}

TEST(H5md, RoundTripObservables) {
  const ScratchDir dir;
  const fs::path file = dir.path() / "traj.h5";
  write_test_file(file);

  const auto a = read_h5md_observable(file, "stress_xy");
  const auto b = read_h5md_observable(file, "energy");
  ASSERT_EQ(a.value.size(), 3u);
  ASSERT_EQ(b.value.size(), 3u);
  for (int f = 0; f < kFrames; ++f) {
    EXPECT_EQ(a.step[f], step_at(f));
    EXPECT_EQ(a.time[f], time_at(f));
    EXPECT_EQ(a.value[f], obs_a(f));
    EXPECT_EQ(b.step[f], step_at(f));
    EXPECT_EQ(b.time[f], time_at(f));
    EXPECT_EQ(b.value[f], obs_b(f));
  }
  try {
    read_h5md_observable(file, "missing");
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("/observables/missing"), std::string::npos) << msg;
    EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
  }
}

TEST(H5md, LayoutViaCApi) {
  const ScratchDir dir;
  const fs::path file = dir.path() / "traj.h5";
  write_test_file(file);

  const hid_t f = H5Fopen(file.string().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);

  int version[2] = {0, 0};
  const hid_t va = H5Aopen_by_name(f, "/h5md", "version", H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(va, 0);
  ASSERT_GE(H5Aread(va, H5T_NATIVE_INT, version), 0);
  H5Aclose(va);
  EXPECT_EQ(version[0], 1);
  EXPECT_EQ(version[1], 1);

  int dimension = 0;
  const hid_t da =
      H5Aopen_by_name(f, "/particles/suspension/box", "dimension", H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(da, 0);
  ASSERT_GE(H5Aread(da, H5T_NATIVE_INT, &dimension), 0);
  H5Aclose(da);
  EXPECT_EQ(dimension, 2);

  // H5MD 1.1: box/boundary is a fixed-length string array.
  const hid_t ba =
      H5Aopen_by_name(f, "/particles/suspension/box", "boundary", H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(ba, 0);
  const hid_t bt = H5Aget_type(ba);
  EXPECT_EQ(H5Tis_variable_str(bt), 0);
  const std::size_t width = H5Tget_size(bt);
  std::vector<char> bnd(2 * width + 1, '\0');
  ASSERT_GE(H5Aread(ba, bt, bnd.data()), 0);
  EXPECT_STREQ(bnd.data(), "periodic");
  EXPECT_STREQ(bnd.data() + width, "periodic");
  H5Tclose(bt);
  H5Aclose(ba);

  // Variable-length UTF-8 string attributes: HDF5 has no ASCII<->UTF-8 conversion.
  const hid_t st = H5Tcopy(H5T_C_S1);
  H5Tset_size(st, H5T_VARIABLE);
  H5Tset_cset(st, H5T_CSET_UTF8);
  char* config = nullptr;
  const hid_t ca = H5Aopen_by_name(f, "/parameters", "config", H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(ca, 0);
  ASSERT_GE(H5Aread(ca, st, &config), 0);
  EXPECT_STREQ(config, "[scene]\nkind = \"shear\"\n");
  H5free_memory(config);
  H5Aclose(ca);
  H5Tclose(st);

  // Chunked, extensible position dataset of shape (3, 5, 2).
  const hid_t ds = H5Dopen2(f, "/particles/suspension/position/value", H5P_DEFAULT);
  ASSERT_GE(ds, 0);
  const hid_t sp = H5Dget_space(ds);
  hsize_t dims[3] = {0, 0, 0}, maxdims[3] = {0, 0, 0};
  ASSERT_EQ(H5Sget_simple_extent_dims(sp, dims, maxdims), 3);
  EXPECT_EQ(dims[0], 3u);
  EXPECT_EQ(dims[1], 5u);
  EXPECT_EQ(dims[2], 2u);
  EXPECT_EQ(maxdims[0], H5S_UNLIMITED);
  H5Sclose(sp);
  H5Dclose(ds);

  // A table: one time-independent element per column.
  double column[2] = {};
  const hid_t ts = H5Dopen2(f, "/observables/profile/phi", H5P_DEFAULT);
  ASSERT_GE(ts, 0);
  ASSERT_GE(H5Dread(ts, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, column), 0);
  H5Dclose(ts);
  EXPECT_EQ(column[0], 3.0);
  EXPECT_EQ(column[1], 6.0);

  H5Fclose(f);
}

TEST(H5md, WriterRejectsBadFrames) {
  const ScratchDir dir;
  const fs::path file = dir.path() / "bad.h5";
  H5mdWriter w(file, make_layout());
  std::vector<Vec2> p(kN, Vec2::Zero()), short_p(kN - 1, Vec2::Zero());
  std::vector<Vec3> v(kN, Vec3::Zero());
  FrameData fd;
  fd.position = &short_p;
  fd.velocity = &v;
  fd.observables = {0.0, 0.0};
  EXPECT_THROW(w.write_frame(fd), std::runtime_error);
  fd.position = &p;
  fd.observables = {0.0};
  EXPECT_THROW(w.write_frame(fd), std::runtime_error);
  fd.observables = {0.0, 0.0};
  fd.velocity = nullptr;
  EXPECT_THROW(w.write_frame(fd), std::runtime_error);
  fd.velocity = &v;
  w.write_frame(fd);  // no unwrapped at frame 0: the element is never written
  EXPECT_EQ(w.frames_written(), 1);
  w.flush();
  const H5mdFrame fr = read_h5md_frame(file);
  EXPECT_EQ(fr.position.size(), kN);
  EXPECT_TRUE(fr.unwrapped.empty());
}

TEST(H5md, MissingFileThrowsNamingPath) {
  const fs::path missing = fs::temp_directory_path() / "sheardiff_definitely_missing_file.h5";
  for (const auto& call : {+[](const fs::path& p) { (void)count_h5md_frames(p); },
                           +[](const fs::path& p) { (void)read_h5md_frame(p, 0); }}) {
    try {
      call(missing);
      FAIL() << "expected an exception";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
    }
  }
}

haddr_t address(hid_t f, const std::string& name) {
  H5O_info_t info{};
  EXPECT_GE(H5Oget_info_by_name2(f, name.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT), 0) << name;
  return info.addr;
}

std::string unit_of(hid_t f, const std::string& name) {
  if (H5Aexists_by_name(f, name.c_str(), "unit", H5P_DEFAULT) <= 0) return "<none>";
  const hid_t a = H5Aopen_by_name(f, name.c_str(), "unit", H5P_DEFAULT, H5P_DEFAULT);
  const hid_t t = H5Tcopy(H5T_C_S1);
  H5Tset_size(t, H5T_VARIABLE);
  H5Tset_cset(t, H5T_CSET_ASCII);
  char* u = nullptr;
  EXPECT_GE(H5Aread(a, t, &u), 0) << name;
  std::string out = u != nullptr ? u : "";
  H5free_memory(u);
  H5Tclose(t);
  H5Aclose(a);
  return out;
}

const std::string kG = "/particles/suspension/";

TEST(H5md, BoxIsATriclinicMatrixAndStepTimeAreHardLinks) {
  const ScratchDir dir;
  const fs::path file = dir.path() / "traj.h5";
  write_test_file(file);
  const hid_t f = H5Fopen(file.string().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);

  const hid_t ds = H5Dopen2(f, (kG + "box/edges/value").c_str(), H5P_DEFAULT);
  const hid_t sp = H5Dget_space(ds);
  hsize_t dims[3] = {};
  ASSERT_EQ(H5Sget_simple_extent_dims(sp, dims, nullptr), 3);
  EXPECT_EQ(dims[0], 3u);
  EXPECT_EQ(dims[1], 2u);
  EXPECT_EQ(dims[2], 2u);
  double edges[3][2][2] = {};
  ASSERT_GE(H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, edges), 0);
  H5Sclose(sp);
  H5Dclose(ds);
  const double reduced[3] = {1.0, 2.0, -3.0};
  for (int k = 0; k < kFrames; ++k) {
    EXPECT_EQ(edges[k][0][0], 6.0);
    EXPECT_EQ(edges[k][0][1], 0.0);
    EXPECT_EQ(edges[k][1][0], reduced[k]);
    EXPECT_EQ(edges[k][1][1], ly_at(k));
  }

  const haddr_t step = address(f, kG + "position/step");
  const haddr_t time = address(f, kG + "position/time");
  EXPECT_NE(step, time);
  for (const std::string& e :
       {kG + "box/edges", kG + "velocity", kG + "angular_velocity", kG + "image",
        kG + "unwrapped_position", std::string("/observables/stress_xy"),
        std::string("/observables/energy")}) {
    EXPECT_EQ(address(f, e + "/step"), step) << e;
    EXPECT_EQ(address(f, e + "/time"), time) << e;
  }

  // image: position + image . edges lands within half a cell of the unwrapped position.
  std::int32_t image[kFrames][kN][2] = {};
  const hid_t is = H5Dopen2(f, (kG + "image/value").c_str(), H5P_DEFAULT);
  ASSERT_GE(H5Dread(is, H5T_NATIVE_INT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, image), 0);
  H5Dclose(is);
  for (int k = 0; k < kFrames; ++k) {
    for (std::size_t i = 0; i < kN; ++i) {
      const Vec2 r =
          pos(k, i) + image[k][i][0] * Vec2(6.0, 0.0) + image[k][i][1] * Vec2(reduced[k], ly_at(k));
      EXPECT_LE(std::abs(r.y() - unw(k, i).y()), 0.5 * ly_at(k)) << k << " " << i;
      EXPECT_LE(std::abs(r.x() - unw(k, i).x()), 3.0) << k << " " << i;
    }
  }
  H5Fclose(f);
}

TEST(H5md, EveryElementHasAUnitAndTheCodesNameThemselves) {
  const ScratchDir dir;
  const fs::path file = dir.path() / "traj.h5";
  write_test_file(file);
  const hid_t f = H5Fopen(file.string().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  const std::vector<std::pair<std::string, std::string>> want = {
      {kG + "position/value", "d"},
      {kG + "position/time", "eta P-1"},
      {kG + "box/edges/value", "d"},
      {kG + "velocity/value", "P d eta-1"},
      {kG + "angular_velocity/value", "P eta-1"},
      {kG + "image/value", "1"},
      {kG + "unwrapped_position/value", "d"},
      {kG + "diameter", "d"},
      {kG + "species", "1"},
      {kG + "motion", "1"},
      {"/observables/stress_xy/value", "1"},
      {"/observables/profile/y", "d"},
      {"/observables/profile/u_x", "P d eta-1"},
  };
  for (const auto& [name, unit] : want) EXPECT_EQ(unit_of(f, name), unit) << name;

  int version[2] = {};
  const hid_t va = H5Aopen_by_name(f, "/h5md/modules/units", "version", H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(va, 0);
  ASSERT_GE(H5Aread(va, H5T_NATIVE_INT, version), 0);
  H5Aclose(va);
  EXPECT_EQ(version[0], 1);
  EXPECT_EQ(version[1], 0);

  const hid_t motion = H5Dopen2(f, (kG + "motion").c_str(), H5P_DEFAULT);
  const hid_t type = H5Dget_type(motion);
  ASSERT_EQ(H5Tget_class(type), H5T_ENUM);
  char name[32] = {};
  const std::int8_t code = 2;
  ASSERT_GE(H5Tenum_nameof(type, &code, name, sizeof name), 0);
  EXPECT_STREQ(name, "floating_wall");
  H5Tclose(type);
  H5Dclose(motion);
  H5Fclose(f);
}

ContactNetwork network_at(int f) {
  ContactNetwork c;
  for (int k = 0; k < (f == 1 ? 0 : 2 + f); ++k) {
    c.pairs.push_back({k, (k + 1 + f) % static_cast<int>(kN)});
    c.normal_force.push_back(0.5 * k + f);
    c.tangential_force.push_back(-0.25 * k);
    c.sliding.push_back(k % 2);
  }
  return c;
}

void write_contact_frames(H5mdWriter& w, int from, int to) {
  std::vector<Vec2> p(kN, Vec2::Zero());
  std::vector<Vec3> v(kN, Vec3::Zero());
  for (int f = from; f < to; ++f) {
    const ContactNetwork c = network_at(f);
    FrameData fd;
    fd.step = step_at(f);
    fd.time = time_at(f);
    fd.lx = 6;
    fd.ly = 8;
    fd.position = &p;
    fd.velocity = &v;
    fd.contacts = &c;
    fd.observables = {0.0, 0.0};
    w.write_frame(fd);
  }
}

void expect_network(const ContactNetwork& got, int f) {
  const ContactNetwork want = network_at(f);
  EXPECT_EQ(got.pairs, want.pairs) << "frame " << f;
  EXPECT_EQ(got.normal_force, want.normal_force) << "frame " << f;
  EXPECT_EQ(got.tangential_force, want.tangential_force) << "frame " << f;
  EXPECT_EQ(got.sliding, want.sliding) << "frame " << f;
}

TEST(H5md, ContactNetworkRoundTripAndResume) {
  const ScratchDir dir;
  const fs::path file = dir.path() / "traj.h5";
  TrajectoryLayout layout = make_layout();
  layout.write_contacts = true;
  {
    H5mdWriter w(file, layout);
    write_contact_frames(w, 0, kFrames);
    FrameData bad;
    std::vector<Vec2> p(kN, Vec2::Zero());
    std::vector<Vec3> v(kN, Vec3::Zero());
    bad.position = &p;
    bad.velocity = &v;
    bad.observables = {0.0, 0.0};
    EXPECT_THROW(w.write_frame(bad), std::runtime_error);  // no network
  }
  for (int f = 0; f < kFrames; ++f) expect_network(read_h5md_contacts(file, f), f);
  {
    // Back to the first two frames, then a different third one.
    H5mdWriter w = H5mdWriter::resume(file, layout, 2);
    write_contact_frames(w, 0, 1);
  }
  EXPECT_EQ(count_h5md_frames(file), kFrames);
  expect_network(read_h5md_contacts(file, 0), 0);
  expect_network(read_h5md_contacts(file, 1), 1);
  expect_network(read_h5md_contacts(file, 2), 0);

  const hid_t f = H5Fopen(file.string().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  EXPECT_EQ(address(f, "/connectivity/contacts/step"), address(f, kG + "position/step"));
  hobj_ref_t ref{};
  const hid_t a =
      H5Aopen_by_name(f, "/connectivity/contacts", "particles_group", H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(a, 0);
  ASSERT_GE(H5Aread(a, H5T_STD_REF_OBJ, &ref), 0);
  H5Aclose(a);
  const hid_t g = H5Rdereference2(f, H5P_DEFAULT, H5R_OBJECT, &ref);
  ASSERT_GE(g, 0);
  char name[64] = {};
  H5Iget_name(g, name, sizeof name);
  EXPECT_STREQ(name, "/particles/suspension");
  H5Oclose(g);
  H5Fclose(f);
}

// A minimal file as another writer might make it: group "all", a time-independent 3D
// triclinic box, fixed step/time storage, float32 positions, integer species.
void write_foreign_file(const fs::path& file) {
  const hid_t f = H5Fcreate(file.string().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  const auto group = [&](const char* name) {
    H5Gclose(H5Gcreate2(f, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  };
  group("/h5md");
  group("/particles");
  group("/particles/all");
  group("/particles/all/box");
  group("/particles/all/position");
  const hid_t box = H5Gopen2(f, "/particles/all/box", H5P_DEFAULT);
  const hid_t scalar = H5Screate(H5S_SCALAR);
  const int three = 3;
  hid_t a = H5Acreate2(box, "dimension", H5T_STD_I32LE, scalar, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, H5T_NATIVE_INT, &three);
  H5Aclose(a);
  const hid_t vl = H5Tcopy(H5T_C_S1);
  H5Tset_size(vl, H5T_VARIABLE);
  const hsize_t three_dims[1] = {3};
  const hid_t s3 = H5Screate_simple(1, three_dims, nullptr);
  const char* bnd[3] = {"periodic", "periodic", "periodic"};
  a = H5Acreate2(box, "boundary", vl, s3, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, vl, bnd);
  H5Aclose(a);
  H5Sclose(s3);
  H5Tclose(vl);
  H5Gclose(box);
  const auto dataset = [&](const char* name, hid_t type, std::vector<hsize_t> dims,
                           const void* data, hid_t mem) {
    const hid_t sp = dims.empty()
                         ? H5Screate(H5S_SCALAR)
                         : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
    const hid_t ds = H5Dcreate2(f, name, type, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(ds, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
    H5Sclose(sp);
    return ds;
  };
  const double edges[3][3] = {{5, 0, 0}, {1.5, 4, 0}, {0, 0, 9}};
  H5Dclose(dataset("/particles/all/box/edges", H5T_IEEE_F64LE, {3, 3}, edges, H5T_NATIVE_DOUBLE));
  const long step = 10, offset = 100;
  const hid_t st =
      dataset("/particles/all/position/step", H5T_STD_I64LE, {}, &step, H5T_NATIVE_LONG);
  a = H5Acreate2(st, "offset", H5T_STD_I64LE, scalar, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, H5T_NATIVE_LONG, &offset);
  H5Aclose(a);
  H5Dclose(st);
  const double dt = 0.5;
  H5Dclose(dataset("/particles/all/position/time", H5T_IEEE_F64LE, {}, &dt, H5T_NATIVE_DOUBLE));
  const float xyz[2][2][3] = {{{1, 2, 0}, {3, 1, 0}}, {{1.5f, 2.5f, 0}, {3.5f, 0.5f, 0}}};
  H5Dclose(
      dataset("/particles/all/position/value", H5T_IEEE_F32LE, {2, 2, 3}, xyz, H5T_NATIVE_FLOAT));
  const int species[2] = {0, 1};
  H5Dclose(dataset("/particles/all/species", H5T_STD_I32LE, {2}, species, H5T_NATIVE_INT));
  H5Sclose(scalar);
  H5Fclose(f);
}

TEST(H5md, ReadsAnotherWritersFileQuietly) {
  const ScratchDir dir;
  const fs::path file = dir.path() / "foreign.h5";
  write_foreign_file(file);
  testing::internal::CaptureStderr();
  const long frames = count_h5md_frames(file);
  const H5mdFrame fr = read_h5md_frame(file, 1);
  const std::string noise = testing::internal::GetCapturedStderr();
  EXPECT_EQ(noise, "");
  EXPECT_EQ(frames, 2);
  EXPECT_EQ(fr.step, 110);
  EXPECT_EQ(fr.time, 0.5);
  EXPECT_EQ(fr.lx, 5.0);
  EXPECT_EQ(fr.ly, 4.0);
  EXPECT_EQ(fr.tilt, 1.5);
  ASSERT_EQ(fr.position.size(), 2u);
  EXPECT_EQ(fr.position[1], Vec2(3.5, 0.5));
  EXPECT_EQ(fr.species, (std::vector<int>{0, 1}));
  EXPECT_TRUE(fr.motion.empty());
  EXPECT_TRUE(read_h5md_contacts(file).pairs.empty());
}

// The layout before issue 17: a cuboid box vector per frame with its own step and time.
TEST(H5md, ReadsTheOldCuboidLayout) {
  const ScratchDir dir;
  const fs::path file = dir.path() / "old.h5";
  const hid_t f = H5Fcreate(file.string().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  for (const char* g : {"/particles", "/particles/suspension", "/particles/suspension/box",
                        "/particles/suspension/box/edges", "/particles/suspension/position"})
    H5Gclose(H5Gcreate2(f, g, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
  const hid_t box = H5Gopen2(f, "/particles/suspension/box", H5P_DEFAULT);
  const hid_t vl = H5Tcopy(H5T_C_S1);
  H5Tset_size(vl, H5T_VARIABLE);
  H5Tset_cset(vl, H5T_CSET_UTF8);
  const hsize_t two[1] = {2};
  const hid_t s2 = H5Screate_simple(1, two, nullptr);
  const char* bnd[2] = {"periodic", "periodic"};
  const hid_t a = H5Acreate2(box, "boundary", vl, s2, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, vl, bnd);
  H5Aclose(a);
  H5Sclose(s2);
  H5Tclose(vl);
  H5Gclose(box);
  const auto dataset = [&](const char* name, hid_t type, std::vector<hsize_t> dims,
                           const void* data, hid_t mem) {
    const hid_t sp = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
    H5Dclose(H5Dcreate2(f, name, type, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
    const hid_t ds = H5Dopen2(f, name, H5P_DEFAULT);
    H5Dwrite(ds, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
    H5Dclose(ds);
    H5Sclose(sp);
  };
  const std::int64_t step[1] = {40};
  const double time[1] = {2.0}, edges[1][2] = {{6.0, 7.0}}, xy[1][1][2] = {{{1.0, 2.0}}};
  const int motion[1] = {0};
  for (const char* e : {"box/edges", "position"}) {
    dataset((kG + e + "/step").c_str(), H5T_STD_I64LE, {1}, step, H5T_NATIVE_INT64);
    dataset((kG + e + "/time").c_str(), H5T_IEEE_F64LE, {1}, time, H5T_NATIVE_DOUBLE);
  }
  dataset((kG + "box/edges/value").c_str(), H5T_IEEE_F64LE, {1, 2}, edges, H5T_NATIVE_DOUBLE);
  dataset((kG + "position/value").c_str(), H5T_IEEE_F64LE, {1, 1, 2}, xy, H5T_NATIVE_DOUBLE);
  dataset((kG + "motion").c_str(), H5T_STD_I32LE, {1}, motion, H5T_NATIVE_INT);
  H5Fclose(f);

  const H5mdFrame fr = read_h5md_frame(file);
  EXPECT_EQ(fr.step, 40);
  EXPECT_EQ(fr.lx, 6.0);
  EXPECT_EQ(fr.ly, 7.0);
  EXPECT_EQ(fr.tilt, 0.0);
  EXPECT_EQ(fr.position[0], Vec2(1.0, 2.0));
  EXPECT_EQ(fr.motion, (std::vector<int>{0}));
}

TEST(PositionTable, ReadsWithCommentsAndBlankLines) {
  const ScratchDir dir;
  const fs::path file = dir.path() / "pos.txt";
  {
    std::ofstream out(file);
    out << "# x y diameter\n"
        << "0.5 1.25 1.0\n"
        << "\n"
        << "   \t \n"
        << "-2 3e-1 1.4  # large one\n"
        << "+4.75\t-0.5\t1\n";
  }
  const TableConfiguration t = read_position_table(file);
  ASSERT_EQ(t.position.size(), 3u);
  ASSERT_EQ(t.diameter.size(), 3u);
  EXPECT_EQ(t.position[0], Vec2(0.5, 1.25));
  EXPECT_EQ(t.position[1], Vec2(-2.0, 0.3));
  EXPECT_EQ(t.position[2], Vec2(4.75, -0.5));
  EXPECT_EQ(t.diameter, (std::vector<double>{1.0, 1.4, 1.0}));
}

TEST(PositionTable, MalformedLineThrowsWithLineNumber) {
  const ScratchDir dir;
  const fs::path file = dir.path() / "bad.txt";
  {
    std::ofstream out(file);
    out << "# header\n"
        << "0 0 1\n"
        << "\n"
        << "1 2 oops\n";
  }
  try {
    read_position_table(file);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("line 4"), std::string::npos) << msg;
    EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
  }
  {
    std::ofstream out(file);
    out << "0 0 1\n1 2\n";
  }
  try {
    read_position_table(file);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  }
}

TEST(PositionTable, MissingFileThrowsNamingPath) {
  const fs::path missing = fs::temp_directory_path() / "sheardiff_definitely_missing_table.txt";
  try {
    read_position_table(missing);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing.string()), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sheardiff
