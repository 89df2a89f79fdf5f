// Pressure-imposed plane shear: a monolayer between two rough walls of frozen particles, the
// bottom wall fixed, the top wall driven with the flow and floating under the load P Lx lz.
#include <algorithm>
#include <random>

#include "sheardiff/scene/scene.hpp"
#include "sheardiff/setup/random_packing.hpp"

namespace sheardiff {

namespace {

struct WallDisc {
  double x, y, r;
  int species;
};

// One disordered row of bidisperse discs spanning the periodic length lx, neighbours slightly
// overlapping so that no mobile disc can slip through; centres at base +/- (r + jitter).
std::vector<WallDisc> rough_wall(double lx, double base, int side, const Config& cfg,
                                 std::mt19937_64& rng) {
  const double ratio = cfg.particles.size_ratio;
  const std::vector<int> pool = bidisperse_species(1000, cfg.particles.mix, ratio);
  const double large_fraction =
      static_cast<double>(std::count(pool.begin(), pool.end(), 1)) / pool.size();
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::vector<WallDisc> row;
  double length = 0.0;
  while (length < lx) {
    const int sp = uni(rng) < large_fraction ? 1 : 0;
    const double r = sp == 1 ? 0.5 * ratio : 0.5;
    row.push_back({0.0, 0.0, r, sp});
    length += 2.0 * r;
  }
  // Squeeze the row onto lx (a few percent overlap between neighbours).
  const double squeeze = lx / length;
  double x = 0.0;
  for (WallDisc& w : row) {
    w.x = x + w.r * squeeze;
    x += 2.0 * w.r * squeeze;
    w.y = base + side * (w.r + cfg.walls.jitter * w.r * uni(rng));
  }
  return row;
}

}  // namespace

Scene build_pressure_shear(const Config& cfg) {
  Packing pk = initial_packing(cfg, false);
  std::mt19937_64 rng(static_cast<std::uint64_t>(cfg.run.seed) ^ 0x9e3779b97f4a7c15ULL);
  const double lx = pk.lx;
  double amax = 0.0;
  for (double a : pk.radius) amax = std::max(amax, a);
  // The packing was made periodic in y; between walls it is cut open, so it is offset by one
  // large radius plus a small margin from each wall surface.
  const double margin = 0.05;
  const auto bottom = rough_wall(lx, 0.0, -1, cfg, rng);
  double ymin = 1e300, ymax = -1e300;
  for (const Vec2& x : pk.position) ymin = std::min(ymin, x.y()), ymax = std::max(ymax, x.y());
  const double shift = amax + margin - ymin;
  const double fill_top = ymax + shift + amax + margin;
  const auto top = rough_wall(lx, fill_top, +1, cfg, rng);

  Scene sc;
  const std::size_t n = pk.position.size();
  sc.particles.resize(n + bottom.size() + top.size());
  sc.particles.n_mobile = n;
  for (std::size_t i = 0; i < n; ++i) {
    sc.particles.position[i] = pk.position[i] + Vec2(0.0, shift);
    sc.particles.radius[i] = pk.radius[i];
    sc.particles.species[i] = pk.species[i];
  }
  WallBodies walls;
  walls.top_role = WallRole::Floating;
  std::size_t k = n;
  for (const auto* row : {&bottom, &top}) {
    const bool is_top = row == &top;
    for (const WallDisc& w : *row) {
      sc.particles.position[k] = Vec2(w.x, w.y);
      sc.particles.radius[k] = w.r;
      sc.particles.species[k] = w.species;
      sc.particles.motion[k] = is_top ? Motion::FloatingWall : Motion::FixedWall;
      (is_top ? walls.top : walls.bottom).push_back(static_cast<int>(k));
      ++k;
    }
  }
  sc.particles.unwrapped = sc.particles.position;
  walls.load = 1.0 * lx * cfg.flow.lz;  // P Lx lz with P = 1
  walls.free_fall_cap = cfg.walls.free_fall_speed;

  double y_bottom = 0.0;
  for (int b : walls.bottom) y_bottom += sc.particles.position[b].y();
  y_bottom /= static_cast<double>(walls.bottom.size());

  sc.box.lx = lx;
  sc.box.ly = fill_top + 2.0 * amax;  // extent at the start; not periodic in y
  sc.box.lees_edwards = false;
  sc.flow.gammadot = cfg.flow.j;
  sc.flow.y0 = y_bottom;
  sc.walls = std::move(walls);
  return sc;
}

}  // namespace sheardiff
