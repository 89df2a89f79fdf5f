// The pressure cell of spheres (scene/scene.hpp): bidisperse spheres (a random start compressed
// to particles.phi_init_spheres, or a loose lattice) between two rough walls of frozen spheres,
// periodic in x and z.
#include <algorithm>
#include <cmath>
#include <random>

#include "sheardiff/scene/scene.hpp"
#include "sheardiff/setup/random_packing.hpp"

namespace sheardiff {

namespace {

// One rough wall: floor(lx) spheres of diameter 1 a side on a square lattice filling lx x lz
// (gaps of up to 1/floor(lx) between them where lx is not a whole number of diameters: they
// follow the cell's width), centres at base + side (a + jitter a u), u in [0, 1).
void add_wall(Particles3& p, std::vector<int>& ids, double l, double base, int side, double jitter,
              Motion motion, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const int per_side = std::max(1, static_cast<int>(std::floor(l)));
  const double spacing = l / per_side, a = 0.5;
  for (int ix = 0; ix < per_side; ++ix)
    for (int iz = 0; iz < per_side; ++iz) {
      const std::size_t k = p.size();
      p.resize(k + 1);
      p.position[k] = Space3((ix + 0.5) * spacing, base + side * (a + jitter * a * uni(rng)),
                             (iz + 0.5) * spacing);
      p.radius[k] = a;
      p.motion[k] = motion;
      ids.push_back(static_cast<int>(k));
    }
}

// Lattice sites one largest diameter plus a margin apart, per_side x per_side in x-z, with
// about particles.aspect times per_side layers in y (per_side^2 layers = N).
double site_spacing(const Config& cfg) {
  return std::max(1.0, cfg.particles.size_ratio) + 0.1;
}
int sites_per_side(const Config& cfg) {
  const double n = static_cast<double>(cfg.particles.n);
  return std::max(2, static_cast<int>(std::lround(std::cbrt(n / cfg.particles.aspect))));
}

// The random start at particles.phi_init_spheres (setup/sphere_packing.cpp).
SpherePacking random_start(const Config& cfg) {
  return random_sphere_packing(cfg.particles.n, cfg.particles.mix, cfg.particles.size_ratio,
                               cfg.particles.phi_init_spheres, cfg.particles.aspect, false,
                               static_cast<std::uint64_t>(cfg.run.seed) ^ 0x51ab7c3d9e3779b9ULL);
}

}  // namespace

PlannedCell pressure_shear_3d_cell(const Config& cfg) {
  if (cfg.particles.phi_init_spheres > 0.0) {
    const SphereCell c =
        sphere_packing_cell(cfg.particles.n, cfg.particles.mix, cfg.particles.size_ratio,
                            cfg.particles.phi_init_spheres, cfg.particles.aspect);
    return {.lx = c.l, .ly = c.ly, .lz = c.l};
  }
  const int per_side = sites_per_side(cfg);
  const double spacing = site_spacing(cfg), l = per_side * spacing;
  const auto layers =
      static_cast<double>((cfg.particles.n + per_side * per_side - 1) / (per_side * per_side));
  return {.lx = l, .ly = (layers + 1.0) * spacing, .lz = l};
}

Scene3 build_pressure_shear_3d(const Config& cfg) {
  const std::int64_t n = cfg.particles.n;
  const double ratio = cfg.particles.size_ratio;
  std::mt19937_64 rng(static_cast<std::uint64_t>(cfg.run.seed) ^ 0x51ab7c3d9e3779b9ULL);
  Scene3 sc;
  Particles3& p = sc.particles;
  p.resize(static_cast<std::size_t>(n));
  p.n_mobile = static_cast<std::size_t>(n);
  double l = 0.0, top = 0.0;
  if (cfg.particles.phi_init_spheres > 0.0) {
    // Random spheres between the walls' surfaces y = 0 and y = top.
    const SpherePacking pk = random_start(cfg);
    for (std::int64_t k = 0; k < n; ++k) {
      p.position[k] = pk.position[k];
      p.species[k] = pk.species[k];
      p.radius[k] = pk.radius[k];
    }
    l = pk.l, top = pk.ly;
  } else {
    std::vector<int> species = bidisperse_species(n, cfg.particles.mix, ratio);
    std::shuffle(species.begin(), species.end(), rng);
    // As many layers of sites in y as it takes; each centre jittered by up to 0.02 spacing per
    // axis, so that no two spheres touch (1.5 - 0.06 > 1.4 at the default size ratio).
    const double spacing = site_spacing(cfg);
    const int per_side = sites_per_side(cfg);
    const auto layers = static_cast<int>((n + per_side * per_side - 1) / (per_side * per_side));
    l = per_side * spacing;
    std::uniform_real_distribution<double> jitter(-0.02, 0.02);
    for (std::int64_t k = 0; k < n; ++k) {
      const auto site = static_cast<int>(k);
      const int layer = site / (per_side * per_side), ix = (site / per_side) % per_side,
                iz = site % per_side;
      p.position[k] =
          Space3((ix + 0.5 + jitter(rng)) * spacing, (layer + 1.0 + jitter(rng)) * spacing,
                 (iz + 0.5 + jitter(rng)) * spacing);
      p.species[k] = species[k];
      p.radius[k] = species[k] == 1 ? 0.5 * ratio : 0.5;
    }
    // The lowest layer sits one spacing above the bottom wall's surface (y = 0), the top wall
    // one spacing above the highest layer.
    top = (layers + 1.0) * spacing;
  }
  WallBodies walls;
  walls.top_role = WallRole::Floating;
  add_wall(p, walls.bottom, l, 0.0, -1, cfg.walls.jitter, Motion::FixedWall, rng);
  add_wall(p, walls.top, l, top, +1, cfg.walls.jitter, Motion::FloatingWall, rng);
  p.unwrapped = p.position;
  walls.load = 1.0 * l * l;  // P lx lz with P = 1
  walls.free_fall_cap = cfg.walls.free_fall_speed;

  sc.box.lx = sc.box.lz = l;
  sc.box.ly = top + 2.0;  // extent at the start; not periodic in y
  sc.box.lees_edwards = false;
  sc.flow.gammadot = cfg.flow.j;
  sc.flow.y0 = mean_height(p, walls.bottom);
  sc.walls = std::move(walls);
  return sc;
}

}  // namespace sheardiff
