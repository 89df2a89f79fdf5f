#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "sheardiff/io/h5md.hpp"

namespace sheardiff {
namespace {

namespace fs = std::filesystem;

// Unique per process and test so parallel ctest runs do not collide.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    const auto tick = std::chrono::steady_clock::now().time_since_epoch().count();
    path_ = fs::temp_directory_path() / ("sheardiff_h5md_" + std::to_string(::getpid()) + "_" +
                                         std::to_string(tick) + "_" + std::to_string(counter++));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

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
    fd.position = &p;
    fd.unwrapped = &u;
    fd.velocity = &v;
    fd.observables = {obs_a(f), obs_b(f)};
    w.write_frame(fd);
  }
  EXPECT_EQ(w.frames_written(), kFrames);
  Eigen::MatrixXd table(2, 3);
  table << 1, 2, 3, 4, 5, 6;
  w.write_table("profile", {"y", "u_x", "phi"}, table);
}

void expect_frame(const H5mdFrame& fr, int f) {
  EXPECT_EQ(fr.step, step_at(f));
  EXPECT_EQ(fr.time, time_at(f));
  EXPECT_EQ(fr.lx, 6.0);
  EXPECT_EQ(fr.ly, ly_at(f));
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
  TempDir dir;
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
  TempDir dir;
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
  TempDir dir;
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

  // Variable-length UTF-8 string attributes: HDF5 has no ASCII<->UTF-8 conversion.
  const hid_t st = H5Tcopy(H5T_C_S1);
  H5Tset_size(st, H5T_VARIABLE);
  H5Tset_cset(st, H5T_CSET_UTF8);
  char* bnd[2] = {nullptr, nullptr};
  const hid_t ba =
      H5Aopen_by_name(f, "/particles/suspension/box", "boundary", H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(ba, 0);
  ASSERT_GE(H5Aread(ba, st, bnd), 0);
  EXPECT_STREQ(bnd[0], "periodic");
  EXPECT_STREQ(bnd[1], "periodic");
  H5free_memory(bnd[0]);
  H5free_memory(bnd[1]);
  H5Aclose(ba);

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

  // Table written row-major: element (1, 2) of [[1,2,3],[4,5,6]] is 6.
  double table[6] = {};
  const hid_t ts = H5Dopen2(f, "/observables/profile/value", H5P_DEFAULT);
  ASSERT_GE(ts, 0);
  ASSERT_GE(H5Dread(ts, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, table), 0);
  H5Dclose(ts);
  EXPECT_EQ(table[0], 1.0);
  EXPECT_EQ(table[2], 3.0);
  EXPECT_EQ(table[3], 4.0);
  EXPECT_EQ(table[5], 6.0);

  H5Fclose(f);
}

TEST(H5md, WriterRejectsBadFrames) {
  TempDir dir;
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

TEST(PositionTable, ReadsWithCommentsAndBlankLines) {
  TempDir dir;
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
  TempDir dir;
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
