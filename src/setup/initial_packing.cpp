#include <fmt/format.h>

#include <cmath>

#include "sheardiff/io/h5md.hpp"
#include "sheardiff/setup/random_packing.hpp"

namespace sheardiff {

namespace {

// A run's own frames overlap by ~1/ktilde of a diameter; discs much closer than contact (two
// at one spot, a file in other units) would start the contact law from forces it cannot
// resolve. Checked over all pairs: init files are read once, at most some 10^4 discs.
constexpr double kMaxStartOverlap = 0.2;  // of the pair's contact distance

void refuse_overlaps(const Packing& pk, bool periodic_y, const std::filesystem::path& file) {
  const std::size_t n = pk.position.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      double dx = pk.position[j].x() - pk.position[i].x();
      double dy = pk.position[j].y() - pk.position[i].y();
      if (periodic_y && pk.ly > 0.0) {
        const double k = std::round(dy / pk.ly);
        dy -= k * pk.ly;
        dx -= k * pk.tilt;
      }
      if (pk.lx > 0.0) dx -= pk.lx * std::round(dx / pk.lx);
      const double contact = pk.radius[i] + pk.radius[j];
      const double r = std::hypot(dx, dy);
      if (r < (1.0 - kMaxStartOverlap) * contact)
        throw ConfigError(fmt::format(
            "particles.init_file: {}: mobile particles {} and {} (counted from 0) are {:.4g} d "
            "apart, overlapping by {:.0f} % of their contact distance {:.4g} d (at most {:.0f} % "
            "allowed): not a packing to start from; check the file's positions and units",
            file.string(), i, j, r, 100.0 * (1.0 - r / contact), contact,
            100.0 * kMaxStartOverlap));
    }
}

Packing packing_from_file(const Config& cfg, bool periodic_y) {
  const std::filesystem::path file = cfg.particles.init_file;
  Packing pk;
  std::vector<double> diameter;
  const auto ext = file.extension().string();
  if (ext == ".gsd")
    throw ConfigError(fmt::format(
        "particles.init_file: {}: a GSD file is not read; give an H5MD trajectory (.h5, .hdf5, "
        ".h5md: a frame of a run) or a text table of x y diameter",
        file.string()));
  if (ext == ".h5" || ext == ".hdf5" || ext == ".h5md") {
    H5mdFrame f = read_h5md_frame(file, cfg.particles.init_frame);
    for (std::size_t k = 0; k < f.position.size(); ++k) {
      if (!f.motion.empty() && f.motion[k] != 0) continue;  // mobile particles only
      pk.position.push_back(f.position[k]);
      diameter.push_back(f.diameter.empty() ? 1.0 : f.diameter[k]);
    }
    pk.lx = f.lx;
    pk.ly = f.ly;
    if (f.periodic_y) pk.tilt = f.tilt;
  } else {
    TableConfiguration t = read_position_table(file);
    pk.position = t.position;
    diameter = t.diameter;
  }
  double area = 0.0;
  for (double d : diameter) {
    pk.radius.push_back(0.5 * d);
    pk.species.push_back(d > 1.0 + 1e-9 ? 1 : 0);
    area += 0.25 * kPi * d * d;
  }
  if (pk.lx <= 0.0 || pk.ly <= 0.0) {
    pk.lx = std::sqrt(area / cfg.particles.phi_init / cfg.particles.aspect);
    pk.ly = cfg.particles.aspect * pk.lx;
  }
  if (static_cast<std::int64_t>(pk.position.size()) != cfg.particles.n)
    throw ConfigError(
        fmt::format("particles.init_file: {} holds {} mobile particles but "
                    "particles.N = {}",
                    file.string(), pk.position.size(), cfg.particles.n));
  refuse_overlaps(pk, periodic_y, file);
  return pk;
}

}  // namespace

Packing initial_packing(const Config& cfg, bool periodic_y) {
  return cfg.particles.init_file.empty()
             ? random_packing(cfg.particles.n, cfg.particles.mix, cfg.particles.size_ratio,
                              cfg.particles.phi_init, cfg.particles.aspect,
                              static_cast<std::uint64_t>(cfg.run.seed))
             : packing_from_file(cfg, periodic_y);
}

}  // namespace sheardiff
