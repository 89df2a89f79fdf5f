#include "sheardiff/setup/random_packing.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sheardiff {

namespace {

// Uniform grid over a periodic cell, cell size >= largest diameter, for overlap searches.
struct Grid {
  int nx, ny;
  double cx, cy, lx, ly;
  std::vector<std::vector<int>> cells;
  Grid(double lx_, double ly_, double cell)
      : nx(std::max(1, static_cast<int>(lx_ / cell))),
        ny(std::max(1, static_cast<int>(ly_ / cell))),
        cx(lx_ / nx),
        cy(ly_ / ny),
        lx(lx_),
        ly(ly_),
        cells(static_cast<std::size_t>(nx) * ny) {}
  int cell_of(const Vec2& x) const {
    int ix = static_cast<int>(std::floor(x.x() / cx)),
        iy = static_cast<int>(std::floor(x.y() / cy));
    ix = ((ix % nx) + nx) % nx;
    iy = std::clamp(((iy % ny) + ny) % ny, 0, ny - 1);
    return iy * nx + ix;
  }
  void insert(int id, const Vec2& x) { cells[cell_of(x)].push_back(id); }
  template <class F>
  void neighbours(const Vec2& x, F&& f) const {
    const int c = cell_of(x), ix = c % nx, iy = c / nx;
    const int rx = nx < 3 ? 0 : 1, ry = ny < 3 ? 0 : 1;
    for (int dy = -ry; dy <= ry; ++dy)
      for (int dx = -rx; dx <= rx; ++dx) {
        const int jx = (ix + dx + nx) % nx, jy = (iy + dy + ny) % ny;
        for (int id : cells[jy * nx + jx]) f(id);
      }
    if (nx < 3 || ny < 3) {  // tiny cells: fall back to every particle once
      for (int q = 0; q < static_cast<int>(cells.size()); ++q) {
        const int qx = q % nx, qy = q / nx;
        if (std::abs(qx - ix) <= rx && std::abs(qy - iy) <= ry) continue;
        for (int id : cells[q]) f(id);
      }
    }
  }
};

Vec2 min_image(Vec2 d, double lx, double ly, bool periodic_y) {
  d.x() -= lx * std::round(d.x() / lx);
  if (periodic_y) d.y() -= ly * std::round(d.y() / ly);
  return d;
}

// Places the discs of pk (radii set) one by one at random in an lx x ly periodic cell, large
// first; false if one found no free spot.
bool random_sequential_addition(Packing& pk, double lx, double ly, double size_ratio,
                                std::uint64_t seed) {
  const auto n = pk.radius.size();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ux(0.0, lx), uy(0.0, ly);
  const double amax = 0.5 * std::max(1.0, size_ratio);
  Grid grid(lx, ly, 2.0 * amax);
  pk.position.assign(n, Vec2::Zero());
  std::vector<std::size_t> order(n);
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = order.size() - 1 - k;
  for (std::size_t k : order) {
    bool placed = false;
    for (int attempt = 0; attempt < 100000 && !placed; ++attempt) {
      const Vec2 x(ux(rng), uy(rng));
      bool free = true;
      grid.neighbours(x, [&](int j) {
        if (!free) return;
        const Vec2 d = min_image(pk.position[j] - x, lx, ly, true);
        if (d.norm() < pk.radius[k] + pk.radius[j]) free = false;
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

}  // namespace

std::vector<int> bidisperse_species(std::int64_t n, MixRule mix, double size_ratio) {
  // Ratio of small to large numbers.
  double ratio = 1.0;
  if (mix == MixRule::Area) ratio = size_ratio * size_ratio;
  if (mix == MixRule::Volume) ratio = size_ratio * size_ratio * size_ratio;
  const auto n_large = static_cast<std::int64_t>(std::llround(n / (1.0 + ratio)));
  std::vector<int> s(static_cast<std::size_t>(n), 0);
  for (std::int64_t k = n - n_large; k < n; ++k) s[static_cast<std::size_t>(k)] = 1;
  return s;
}

double relax_overlaps(std::vector<Vec2>& position, const std::vector<double>& radius, double lx,
                      double ly, bool periodic_y, double tolerance, int max_iterations) {
  const double amax = *std::max_element(radius.begin(), radius.end());
  const std::size_t n = position.size();
  std::vector<Vec2> push(n);
  double worst = 0.0;
  for (int it = 0; it < max_iterations; ++it) {
    Grid grid(lx, ly, 2.0 * amax);
    for (std::size_t i = 0; i < n; ++i) grid.insert(static_cast<int>(i), position[i]);
    std::fill(push.begin(), push.end(), Vec2::Zero());
    worst = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      grid.neighbours(position[i], [&](int j) {
        if (j <= static_cast<int>(i)) return;
        const Vec2 d = min_image(position[j] - position[i], lx, ly, periodic_y);
        const double r = d.norm(), s = radius[i] + radius[j];
        if (r >= s || r == 0.0) return;
        const Vec2 nrm = d / r;
        worst = std::max(worst, s - r);
        push[i] -= 0.5 * (s - r) * nrm;
        push[j] += 0.5 * (s - r) * nrm;
      });
    }
    if (worst < tolerance) break;
    for (std::size_t i = 0; i < n; ++i) {
      // Over-relaxed steps converge faster; the cap keeps dense starts from scattering.
      Vec2 step = 0.6 * push[i];
      const double len = step.norm();
      if (len > 0.1 * radius[i]) step *= 0.1 * radius[i] / len;
      position[i] += step;
      position[i].x() -= lx * std::floor(position[i].x() / lx);
      if (periodic_y)
        position[i].y() -= ly * std::floor(position[i].y() / ly);
      else
        position[i].y() = std::clamp(position[i].y(), radius[i], ly - radius[i]);
    }
  }
  return worst;
}

Packing random_packing(std::int64_t n, MixRule mix, double size_ratio, double phi, double aspect,
                       std::uint64_t seed) {
  Packing pk;
  pk.species = bidisperse_species(n, mix, size_ratio);
  double area = 0.0;
  for (int s : pk.species) {
    pk.radius.push_back(s == 0 ? 0.5 : 0.5 * size_ratio);
    area += kPi * pk.radius.back() * pk.radius.back();
  }
  pk.lx = std::sqrt(area / phi / aspect);
  pk.ly = aspect * pk.lx;

  // Random sequential addition, large discs first, in a cell dilated to phi_rsa. Small or
  // elongated monodisperse cells can jam below 0.5 (the RSA limit is ~0.55 only for large
  // square cells): then start sparser, the compression below does the rest.
  double phi_rsa = 0.0, scale = 1.0, lx = 0.0, ly = 0.0;
  bool placed_all = false;
  for (const double start : {0.5, 0.4, 0.3, 0.2}) {
    if (phi_rsa > 0.0 && start >= phi) continue;  // the same attempt again
    phi_rsa = std::min(phi, start);
    scale = std::sqrt(phi / phi_rsa);
    lx = pk.lx * scale, ly = pk.ly * scale;
    placed_all = random_sequential_addition(pk, lx, ly, size_ratio, seed);
    if (placed_all) break;
  }
  if (!placed_all)
    throw ConfigError(fmt::format(
        "particles.phi_init: random placement of {} discs (size_ratio {}, aspect {}) failed even "
        "at area fraction {}; use an aspect closer to 1, more particles, or particles.init_file",
        n, size_ratio, aspect, phi_rsa));
  if (scale > 1.0) {
    // Compress towards the target in steps of 0.01 in area fraction, relaxing at each one.
    double cur = phi_rsa;
    double cur_lx = lx, cur_ly = ly;
    while (cur < phi) {
      const double next = std::min(phi, cur + 0.01);
      const double f = std::sqrt(cur / next);
      for (auto& x : pk.position) x *= f;
      cur_lx *= f;
      cur_ly *= f;
      cur = next;
      relax_overlaps(pk.position, pk.radius, cur_lx, cur_ly, true, 1e-4, 2000);
    }
    pk.lx = cur_lx;
    pk.ly = cur_ly;
  }
  return pk;
}

}  // namespace sheardiff
