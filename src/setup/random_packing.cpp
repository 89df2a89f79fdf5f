#include "sheardiff/setup/random_packing.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "packing_steps.hpp"

namespace sheardiff {

namespace {

// Places the discs of pk (radii set) one by one at random in an lx x ly periodic cell, large
// first; false if one found no free spot.
bool random_sequential_addition(Packing& pk, double lx, double ly, double size_ratio,
                                std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ux(0.0, lx), uy(0.0, ly);
  const double amax = 0.5 * std::max(1.0, size_ratio);
  const packing::Cell<Vec2> cell{{lx, ly}, true};
  return packing::add_sequentially(pk.position, pk.radius, cell, 2.0 * amax,
                                   [&](std::size_t) { return Vec2(ux(rng), uy(rng)); });
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
  return packing::relax(position, radius, packing::Cell<Vec2>{{lx, ly}, periodic_y}, tolerance,
                        max_iterations);
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
