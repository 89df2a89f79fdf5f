#pragma once
// H5MD 1.1 trajectory output/input (HDF5 C API kept out of this header) and the plain-text
// position table reader. All errors are IoError (a std::runtime_error) naming the file, the
// object and, where HDF5 recorded one, the operating system's reason.
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "sheardiff/core/contact_network.hpp"
#include "sheardiff/core/types.hpp"

namespace sheardiff {

struct TrajectoryLayout {
  std::size_t n_particles = 0;           // all particles, mobile first then wall particles
  std::vector<int> species;              // 0 small, 1 large (size n_particles)
  std::vector<double> diameter;          // size n_particles
  std::vector<int> motion;               // 0 mobile, 1 fixed wall, 2 floating wall
  double lx = 1, ly = 1;                 // initial box edges
  int dimension = 2;                     // 2: discs; 3: spheres, periodic in z
  bool lees_edwards = false;             // y boundary: "periodic" if true, else "none"
  bool write_velocity = true;            // write velocity and angular_velocity (omega_z or omega)
  bool write_contacts = false;           // write /connectivity/contacts every frame
  std::vector<std::string> observables;  // names of scalar observables written per frame
  // H5MD unit strings in the project's units (docs/trajectory.md), same order as observables;
  // empty: every observable is dimensionless ("1").
  std::vector<std::string> observable_units;
  // /h5md/author@name; empty: $SHEARDIFF_AUTHOR, else the account's name, else "unknown"
  std::string author;
  std::string creator_version;  // e.g. "0.1.0"
  std::string config_toml;      // resolved config text, stored as /parameters@config
};

struct FrameData {
  long step = 0;
  double time = 0;
  double lx = 1, ly = 1;  // box edges at this frame (ly unused where y is not periodic)
  double tilt = 0;        // Lees-Edwards shift of the image at +ly (any multiple of lx added)
  const std::vector<Vec2>* position = nullptr;   // wrapped positions, required
  const std::vector<Vec2>* unwrapped = nullptr;  // optional; only honoured if given at frame 0
  // The images crossed (x, y) with respect to the unwrapped Lees-Edwards offset `tilt`
  // (Particles::image); without them the image is the nearest to the unwrapped position.
  const std::vector<std::array<int, 2>>* image = nullptr;
  const std::vector<Vec3>* velocity = nullptr;  // (u_x,u_y,omega), required if write_velocity
  const ContactNetwork* contacts = nullptr;     // required if write_contacts
  std::vector<double> observables;              // same order as layout.observables
  // Spheres (layout.dimension = 3), in place of position, unwrapped, image and velocity (image
  // counts are required with the unwrapped positions, which are wanted as for discs only under
  // Lees-Edwards: without it position + image . edges is the unwrapped one).
  double lz = 1;  // the periodic depth
  const std::vector<Space3>* position3 = nullptr;
  const std::vector<Space3>* unwrapped3 = nullptr;  // optional; only honoured if given at frame 0
  const std::vector<std::array<int, 3>>* image3 = nullptr;
  const std::vector<Vec6>* velocity6 = nullptr;  // (u, omega)
};

class H5mdWriter {
 public:
  // Creates or truncates `file`. Requires n_particles > 0 and per-particle arrays of that size.
  H5mdWriter(const std::filesystem::path& file, const TrajectoryLayout& layout);
  // Reopens a trajectory written with `layout` to continue it after a checkpoint: every
  // time-dependent dataset is cut back to its first `keep_frames` rows, so frames written after
  // the checkpoint are neither duplicated nor kept. Throws if the file holds fewer frames.
  static H5mdWriter resume(const std::filesystem::path& file, const TrajectoryLayout& layout,
                           long keep_frames);
  ~H5mdWriter();  // flush + close, never throws
  H5mdWriter(const H5mdWriter&) = delete;
  H5mdWriter& operator=(const H5mdWriter&) = delete;
  H5mdWriter(H5mdWriter&&) noexcept;
  H5mdWriter& operator=(H5mdWriter&&) noexcept;

  // Appends one row to every time-dependent dataset. Validates all inputs before writing.
  void write_frame(const FrameData& frame);
  // Time-independent table: one time-independent element /observables/<name>/<column> of
  // shape (rows) per column, each with its H5MD unit string; a table of that name is replaced
  // (the end of a run may be repeated after a kill).
  void write_table(const std::string& name, const std::vector<std::string>& columns,
                   const std::vector<std::string>& units, const Eigen::MatrixXd& values);
  void flush();
  long frames_written() const;

 private:
  struct Impl;
  explicit H5mdWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// One frame of an H5MD particle group: ours, or any writer's with a 2D box (or a 3D one,
// of which x and y are taken). Read from the group "suspension", else "all", else the only one.
// One frame, in the x-y plane: a frame of spheres (dimension 3) keeps x and y of every vector
// and omega_z as the velocity's third entry (what the shear-plane analyses read).
struct H5mdFrame {
  long step = 0;
  double time = 0;
  double lx = 0, ly = 0;
  double tilt = 0;         // x component of the second edge vector (0 for a cuboid box)
  bool periodic_y = true;  // box/boundary[1]; ly is a placeholder where it is "none"
  int dimension = 2;       // of the positions in the file
  std::vector<Vec2> position;
  // Empty if the file has no unwrapped_position and (without Lees-Edwards) no image.
  std::vector<Vec2> unwrapped;
  std::vector<Vec3> velocity;  // (v_x, v_y, omega_z); empty if the file has no velocity
  std::vector<double> diameter;
  std::vector<int> species;
  std::vector<int> motion;
};

// frame = -1 means the last frame; otherwise 0-based; throws if out of range.
H5mdFrame read_h5md_frame(const std::filesystem::path& file, long frame = -1);
long count_h5md_frames(const std::filesystem::path& file);
// The contact network of a frame (frame = -1: the last); empty if none was written.
ContactNetwork read_h5md_contacts(const std::filesystem::path& file, long frame = -1);

// Scalar observable time series; columns truncated to the shortest of step/time/value
// so a file cut short by a crash still reads.
struct ObservableSeries {
  std::vector<long> step;
  std::vector<double> time;
  std::vector<double> value;
};
ObservableSeries read_h5md_observable(const std::filesystem::path& file, const std::string& name);
// Whether the file has the observable (runs of older versions recorded fewer).
bool has_h5md_observable(const std::filesystem::path& file, const std::string& name);

// Plain-text table "x y diameter" (whitespace separated, '#' comments, blank lines ignored).
// Throws naming the file and line number on a malformed line (wrong column count,
// unparsable or non-finite number, diameter <= 0).
struct TableConfiguration {
  std::vector<Vec2> position;
  std::vector<double> diameter;
};
TableConfiguration read_position_table(const std::filesystem::path& file);

}  // namespace sheardiff
