// A random start for spheres, between two walls or in a periodic cell: random sequential
// addition in a dilated cell, then compression with a soft repulsion relaxing the overlaps (the
// 3D counterpart of random_packing.cpp's discs; x and z are periodic, y periodic or bounded by
// the walls).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "packing_steps.hpp"
#include "sheardiff/setup/random_packing.hpp"

namespace sheardiff {

SphereCell sphere_packing_cell(std::int64_t n, MixRule mix, double size_ratio, double phi,
                               double aspect) {
  double volume = 0.0;
  for (int s : bidisperse_species(n, mix, size_ratio))
    volume += 4.0 / 3.0 * kPi * std::pow(s == 0 ? 0.5 : 0.5 * size_ratio, 3);
  const double l = std::cbrt(volume / phi / aspect);
  return {.l = l, .ly = aspect * l};
}

SpherePacking random_sphere_packing(std::int64_t n, MixRule mix, double size_ratio, double phi,
                                    double aspect, bool periodic_y, std::uint64_t seed) {
  SpherePacking pk;
  pk.species = bidisperse_species(n, mix, size_ratio);
  for (int s : pk.species) pk.radius.push_back(s == 0 ? 0.5 : 0.5 * size_ratio);
  const SphereCell planned = sphere_packing_cell(n, mix, size_ratio, phi, aspect);
  pk.l = planned.l;
  pk.ly = planned.ly;
  // Random sequential addition at volume fraction 0.3 at most (its jamming limit is ~0.38) in a
  // dilated cell, then compression to phi in steps of 0.01, relaxing at each: between walls in
  // y alone, in a periodic cell in every direction.
  const double phi_rsa = std::min(phi, 0.3);
  const double grow = periodic_y ? std::cbrt(phi / phi_rsa) : 1.0;
  packing::Cell<Space3> cell{
      {pk.l * grow, pk.ly * (periodic_y ? grow : phi / phi_rsa), pk.l * grow}, periodic_y};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const auto draw = [&](std::size_t k) {
    // Where y is bounded, centres at least a radius inside.
    const double a = pk.radius[k], y0 = periodic_y ? 0.0 : a,
                 span = periodic_y ? cell.side[1] : cell.side[1] - 2 * a;
    return Space3(cell.side[0] * uni(rng), y0 + span * uni(rng), cell.side[2] * uni(rng));
  };
  const double amax = *std::max_element(pk.radius.begin(), pk.radius.end());
  if (!packing::add_sequentially(pk.position, pk.radius, cell, 2.0 * amax, draw))
    throw ConfigError(fmt::format(
        "particles.phi_init_spheres: random placement of {} spheres (size_ratio {}, aspect {}) "
        "failed at volume fraction {}; use more particles or an aspect closer to 1",
        n, size_ratio, aspect, phi_rsa));
  for (double cur = phi_rsa; cur < phi;) {
    const double next = std::min(phi, cur + 0.01);
    if (periodic_y) {
      const double f = std::cbrt(cur / next);
      for (auto& x : pk.position) x *= f;
      for (double& side : cell.side) side *= f;
    } else {
      const double f = cur / next;
      for (auto& x : pk.position) x.y() *= f;
      cell.side[1] *= f;
    }
    cur = next;
    packing::relax(pk.position, pk.radius, cell, 1e-4, 2000);
  }
  pk.l = cell.side[0];
  pk.ly = cell.side[1];
  return pk;
}

}  // namespace sheardiff
