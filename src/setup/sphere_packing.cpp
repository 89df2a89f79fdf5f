// A random start for spheres, between two walls or in a periodic cell: random sequential
// addition in a dilated cell, then compression with a soft repulsion relaxing the overlaps (the
// 3D counterpart of random_packing.cpp's discs; x and z are periodic, y periodic or bounded by
// the walls).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "sheardiff/setup/random_packing.hpp"

namespace sheardiff {

namespace {

// Uniform grid over the cell (periodic in x and z, in y as asked), cell size >= the largest
// diameter, so that overlapping spheres are in the same or adjacent cells.
class SphereGrid {
 public:
  SphereGrid(double l, double ly, bool periodic_y, double cell)
      : periodic_y_(periodic_y),
        n_{std::max(1, static_cast<int>(l / cell)), std::max(1, static_cast<int>(ly / cell)),
           std::max(1, static_cast<int>(l / cell))},
        size_{l / n_[0], ly / n_[1], l / n_[2]},
        cells_(static_cast<std::size_t>(n_[0]) * n_[1] * n_[2]) {}

  void insert(int id, const Space3& x) { cells_[index(coords(x))].push_back(id); }

  // Calls f(j) once for every sphere j in the 3 x 3 x 3 cells around x (fewer where an axis
  // has fewer than three cells).
  template <class F>
  void neighbours(const Space3& x, F&& f) const {
    const std::array<int, 3> c = coords(x);
    std::array<int, 3> lo{}, hi{};
    for (int a = 0; a < 3; ++a) {
      const bool periodic = a != 1 || periodic_y_;
      if (n_[a] < 3 && periodic) {
        lo[a] = 0, hi[a] = n_[a] - 1;  // every cell of a short periodic axis, once
      } else {
        lo[a] = periodic ? c[a] - 1 : std::max(0, c[a] - 1);
        hi[a] = periodic ? c[a] + 1 : std::min(n_[a] - 1, c[a] + 1);
      }
    }
    for (int iy = lo[1]; iy <= hi[1]; ++iy)
      for (int iz = lo[2]; iz <= hi[2]; ++iz)
        for (int ix = lo[0]; ix <= hi[0]; ++ix)
          for (int id : cells_[index({wrap(ix, 0), wrap(iy, 1), wrap(iz, 2)})]) f(id);
  }

 private:
  bool periodic_y_;
  std::array<int, 3> n_;
  std::array<double, 3> size_;
  std::vector<std::vector<int>> cells_;

  int wrap(int i, int a) const { return ((i % n_[a]) + n_[a]) % n_[a]; }
  std::array<int, 3> coords(const Space3& x) const {
    std::array<int, 3> c{};
    for (int a = 0; a < 3; ++a) {
      const int i = static_cast<int>(std::floor(x[a] / size_[a]));
      c[a] = a == 1 && !periodic_y_ ? std::clamp(i, 0, n_[a] - 1) : wrap(i, a);
    }
    return c;
  }
  std::size_t index(const std::array<int, 3>& c) const {
    return (static_cast<std::size_t>(c[1]) * n_[2] + c[2]) * n_[0] + c[0];
  }
};

// The cell: l x ly x l, periodic in x and z, in y if periodic_y.
struct Cell {
  double l, ly;
  bool periodic_y;
  Space3 min_image(Space3 d) const {
    d.x() -= l * std::round(d.x() / l);
    if (periodic_y) d.y() -= ly * std::round(d.y() / ly);
    d.z() -= l * std::round(d.z() / l);
    return d;
  }
  SphereGrid grid(double amax) const { return {l, ly, periodic_y, 2.0 * amax}; }
};

// Places the spheres of pk (radii set) at random in the cell, large first (centres at least a
// radius from the walls where y is bounded); false if one found no free spot.
bool add_sequentially(SpherePacking& pk, const Cell& cell, std::uint64_t seed) {
  const std::size_t n = pk.radius.size();
  const double amax = *std::max_element(pk.radius.begin(), pk.radius.end());
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  SphereGrid grid = cell.grid(amax);
  pk.position.assign(n, Space3::Zero());
  for (std::size_t k = n; k-- > 0;) {
    const double a = pk.radius[k];
    const double y0 = cell.periodic_y ? 0.0 : a, span = cell.periodic_y ? cell.ly : cell.ly - 2 * a;
    bool placed = false;
    for (int attempt = 0; attempt < 100000 && !placed; ++attempt) {
      const Space3 x(cell.l * uni(rng), y0 + span * uni(rng), cell.l * uni(rng));
      bool free = true;
      grid.neighbours(x, [&](int j) {
        if (free && cell.min_image(pk.position[j] - x).norm() < a + pk.radius[j]) free = false;
      });
      if (free) {
        pk.position[k] = x;
        grid.insert(static_cast<int>(k), x);
        placed = true;
      }
    }
    if (!placed) return false;
  }
  return true;
}

// Overdamped steepest descent on a harmonic repulsion between spheres (where y is bounded,
// centres may not pass closer than a radius to the planes y = 0 and y = ly); the largest
// remaining overlap.
double relax(SpherePacking& pk, const Cell& cell, double tolerance, int max_iterations) {
  const std::size_t n = pk.position.size();
  const double amax = *std::max_element(pk.radius.begin(), pk.radius.end());
  std::vector<Space3> push(n);
  double worst = 0.0;
  for (int it = 0; it < max_iterations; ++it) {
    SphereGrid grid = cell.grid(amax);
    for (std::size_t i = 0; i < n; ++i) grid.insert(static_cast<int>(i), pk.position[i]);
    std::fill(push.begin(), push.end(), Space3::Zero());
    worst = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      grid.neighbours(pk.position[i], [&](int j) {
        if (j <= static_cast<int>(i)) return;
        const Space3 d = cell.min_image(pk.position[j] - pk.position[i]);
        const double r = d.norm(), s = pk.radius[i] + pk.radius[j];
        if (r >= s || r == 0.0) return;
        worst = std::max(worst, s - r);
        push[i] -= 0.5 * (s - r) / r * d;
        push[j] += 0.5 * (s - r) / r * d;
      });
    if (worst < tolerance) break;
    for (std::size_t i = 0; i < n; ++i) {
      // As for discs: over-relaxed, capped steps converge fast without scattering a dense start.
      Space3 step = 0.6 * push[i];
      const double len = step.norm(), a = pk.radius[i];
      if (len > 0.1 * a) step *= 0.1 * a / len;
      Space3& x = pk.position[i];
      x += step;
      x.x() -= cell.l * std::floor(x.x() / cell.l);
      x.z() -= cell.l * std::floor(x.z() / cell.l);
      if (cell.periodic_y)
        x.y() -= cell.ly * std::floor(x.y() / cell.ly);
      else
        x.y() = std::clamp(x.y(), a, cell.ly - a);
    }
  }
  return worst;
}

}  // namespace

SpherePacking random_sphere_packing(std::int64_t n, MixRule mix, double size_ratio, double phi,
                                    double aspect, bool periodic_y, std::uint64_t seed) {
  SpherePacking pk;
  pk.species = bidisperse_species(n, mix, size_ratio);
  double volume = 0.0;
  for (int s : pk.species) {
    pk.radius.push_back(s == 0 ? 0.5 : 0.5 * size_ratio);
    volume += 4.0 / 3.0 * kPi * std::pow(pk.radius.back(), 3);
  }
  pk.l = std::cbrt(volume / phi / aspect);
  pk.ly = aspect * pk.l;
  // Random sequential addition at volume fraction 0.3 at most (its jamming limit is ~0.38) in a
  // dilated cell, then compression to phi in steps of 0.01, relaxing at each: between walls in
  // y alone, in a periodic cell in every direction.
  const double phi_rsa = std::min(phi, 0.3);
  const double grow = periodic_y ? std::cbrt(phi / phi_rsa) : 1.0;
  Cell cell{pk.l * grow, pk.ly * (periodic_y ? grow : phi / phi_rsa), periodic_y};
  if (!add_sequentially(pk, cell, seed))
    throw ConfigError(fmt::format(
        "particles.phi_init_spheres: random placement of {} spheres (size_ratio {}, aspect {}) "
        "failed at volume fraction {}; use more particles or an aspect closer to 1",
        n, size_ratio, aspect, phi_rsa));
  for (double cur = phi_rsa; cur < phi;) {
    const double next = std::min(phi, cur + 0.01);
    if (periodic_y) {
      const double f = std::cbrt(cur / next);
      for (auto& x : pk.position) x *= f;
      cell.l *= f;
      cell.ly *= f;
    } else {
      const double f = cur / next;
      for (auto& x : pk.position) x.y() *= f;
      cell.ly *= f;
    }
    cur = next;
    relax(pk, cell, 1e-4, 2000);
  }
  pk.l = cell.l;
  pk.ly = cell.ly;
  return pk;
}

}  // namespace sheardiff
