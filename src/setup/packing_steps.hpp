#pragma once
// What the random starts of discs (random_packing.cpp) and of spheres (sphere_packing.cpp)
// share, for Vec2 or Space3 positions: the cell, a grid for overlap searches, random sequential
// addition and the relaxation of overlaps by a soft repulsion. Private to src/setup.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <vector>

namespace sheardiff::packing {

// A box periodic in x (and z), in y if periodic_y; side[a] along axis a.
template <class V>
struct Cell {
  static constexpr int kDim = static_cast<int>(V::RowsAtCompileTime);
  std::array<double, kDim> side{};
  bool periodic_y = true;

  V min_image(V d) const {
    for (int a = 0; a < kDim; ++a)
      if (a != 1 || periodic_y) d[a] -= side[a] * std::round(d[a] / side[a]);
    return d;
  }
  // Back into the box: periodic axes wrap; a bounded y keeps the centre a radius a inside.
  void wrap(V& x, double a) const {
    for (int axis = 0; axis < kDim; ++axis) {
      if (axis == 1 && !periodic_y)
        x[1] = std::clamp(x[1], a, side[1] - a);
      else
        x[axis] -= side[axis] * std::floor(x[axis] / side[axis]);
    }
  }
};

// A uniform grid over the cell, cells at least `cell` wide (the largest diameter), so that
// overlapping particles are in the same or adjacent cells. Every axis wraps: across a bounded y
// that only adds far candidates, which min_image then finds far.
template <class V>
class Grid {
 public:
  static constexpr int kDim = Cell<V>::kDim;

  Grid(const Cell<V>& c, double cell) {
    std::size_t total = 1;
    for (int a = 0; a < kDim; ++a) {
      n_[a] = std::max(1, static_cast<int>(c.side[a] / cell));
      size_[a] = c.side[a] / n_[a];
      total *= static_cast<std::size_t>(n_[a]);
    }
    cells_.resize(total);
  }

  void insert(int id, const V& x) { cells_[index(coords(x))].push_back(id); }

  // Calls f(j) for every particle j in the cells around x: the 3 x 3 (x 3) block, or, on an
  // axis of fewer than three cells, the own cell and then every cell outside the block.
  template <class F>
  void neighbours(const V& x, F&& f) const {
    const Coords c = coords(x);
    Coords r{};
    bool short_axis = false;
    for (int a = 0; a < kDim; ++a) {
      r[a] = n_[a] < 3 ? 0 : 1;
      short_axis = short_axis || n_[a] < 3;
    }
    const auto visit = [&](const Coords& q) {
      for (int id : cells_[index(q)]) f(id);
    };
    // y outermost, x innermost: the order the overlap sums are taken in.
    for (int dy = -r[1]; dy <= r[1]; ++dy) {
      if constexpr (kDim == 3) {
        for (int dz = -r[2]; dz <= r[2]; ++dz)
          for (int dx = -r[0]; dx <= r[0]; ++dx)
            visit({wrap(c[0] + dx, 0), wrap(c[1] + dy, 1), wrap(c[2] + dz, 2)});
      } else {
        for (int dx = -r[0]; dx <= r[0]; ++dx) visit({wrap(c[0] + dx, 0), wrap(c[1] + dy, 1)});
      }
    }
    if (!short_axis) return;
    for (std::size_t k = 0; k < cells_.size(); ++k) {
      const Coords q = coords_of(k);
      bool in_block = true;
      for (int a = 0; a < kDim; ++a) in_block = in_block && std::abs(q[a] - c[a]) <= r[a];
      if (!in_block) visit(q);
    }
  }

 private:
  using Coords = std::array<int, kDim>;
  Coords n_{};
  std::array<double, kDim> size_{};
  std::vector<std::vector<int>> cells_;

  int wrap(int i, int a) const { return ((i % n_[a]) + n_[a]) % n_[a]; }
  Coords coords(const V& x) const {
    Coords c{};
    for (int a = 0; a < kDim; ++a) c[a] = wrap(static_cast<int>(std::floor(x[a] / size_[a])), a);
    return c;
  }
  // y slowest, then z, x fastest.
  std::size_t index(const Coords& c) const {
    std::size_t i = static_cast<std::size_t>(c[1]);
    if constexpr (kDim == 3)
      i = i * static_cast<std::size_t>(n_[2]) + static_cast<std::size_t>(c[2]);
    return i * static_cast<std::size_t>(n_[0]) + static_cast<std::size_t>(c[0]);
  }
  Coords coords_of(std::size_t i) const {
    Coords c{};
    c[0] = static_cast<int>(i % static_cast<std::size_t>(n_[0]));
    i /= static_cast<std::size_t>(n_[0]);
    if constexpr (kDim == 3) {
      c[2] = static_cast<int>(i % static_cast<std::size_t>(n_[2]));
      i /= static_cast<std::size_t>(n_[2]);
    }
    c[1] = static_cast<int>(i);
    return c;
  }
};

// Random sequential addition: particle k = n-1 .. 0 (large first, as bidisperse_species orders
// them) goes to the first of up to 100000 candidates draw(k) that overlaps none placed before.
// False if one found no free spot.
template <class V, class Draw>
bool add_sequentially(std::vector<V>& position, const std::vector<double>& radius,
                      const Cell<V>& cell, double grid_cell, Draw&& draw) {
  const std::size_t n = radius.size();
  Grid<V> grid(cell, grid_cell);
  position.assign(n, V::Zero());
  for (std::size_t k = n; k-- > 0;) {
    bool placed = false;
    for (int attempt = 0; attempt < 100000 && !placed; ++attempt) {
      const V x = draw(k);
      bool free = true;
      grid.neighbours(x, [&](int j) {
        if (!free) return;
        const V d = cell.min_image(position[static_cast<std::size_t>(j)] - x);
        if (d.norm() < radius[k] + radius[static_cast<std::size_t>(j)]) free = false;
      });
      if (free) {
        position[k] = x;
        grid.insert(static_cast<int>(k), x);
        placed = true;
      }
    }
    if (!placed) return false;
  }
  return true;
}

// Overdamped steepest descent on a harmonic repulsion between overlapping particles until the
// largest overlap is below tolerance (or max_iterations); returns the largest left.
template <class V>
double relax(std::vector<V>& position, const std::vector<double>& radius, const Cell<V>& cell,
             double tolerance, int max_iterations) {
  const double amax = *std::max_element(radius.begin(), radius.end());
  const std::size_t n = position.size();
  std::vector<V> push(n);
  double worst = 0.0;
  for (int it = 0; it < max_iterations; ++it) {
    Grid<V> grid(cell, 2.0 * amax);
    for (std::size_t i = 0; i < n; ++i) grid.insert(static_cast<int>(i), position[i]);
    std::fill(push.begin(), push.end(), V::Zero());
    worst = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      grid.neighbours(position[i], [&](int jj) {
        if (jj <= static_cast<int>(i)) return;
        const auto j = static_cast<std::size_t>(jj);
        const V d = cell.min_image(position[j] - position[i]);
        const double r = d.norm(), s = radius[i] + radius[j];
        if (r >= s || r == 0.0) return;
        const V nrm = d / r;
        worst = std::max(worst, s - r);
        push[i] -= 0.5 * (s - r) * nrm;
        push[j] += 0.5 * (s - r) * nrm;
      });
    }
    if (worst < tolerance) break;
    for (std::size_t i = 0; i < n; ++i) {
      // Over-relaxed steps converge faster; the cap keeps dense starts from scattering.
      V step = 0.6 * push[i];
      const double len = step.norm();
      if (len > 0.1 * radius[i]) step *= 0.1 * radius[i] / len;
      position[i] += step;
      cell.wrap(position[i], radius[i]);
    }
  }
  return worst;
}

}  // namespace sheardiff::packing
