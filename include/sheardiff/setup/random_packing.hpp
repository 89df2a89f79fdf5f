#pragma once
#include <cstdint>
#include <random>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/core/types.hpp"

namespace sheardiff {

// Diameters of a bidisperse mixture of n particles (small = 1, large = size_ratio), mixed by
// equal total area, equal total volume or equal number; small first, then large.
std::vector<int> bidisperse_species(std::int64_t n, MixRule mix, double size_ratio);

struct Packing {
  std::vector<Vec2> position;
  std::vector<double> radius;
  std::vector<int> species;
  double lx = 0, ly = 0;
  double tilt = 0;  // x shift of the image at +ly (a Lees-Edwards cell read from a file)
};

// Random non-overlapping discs in a periodic lx x ly cell at area fraction phi. Random
// sequential addition up to phi = 0.5; denser targets are reached by shrinking the cell in
// small steps and relaxing the overlaps with a soft repulsion (docs/model.md section 2).
// Reproducible for a given seed.
Packing random_packing(std::int64_t n, MixRule mix, double size_ratio, double phi, double aspect,
                       std::uint64_t seed);

// Random non-overlapping spheres in an l x ly x l cell periodic in x and z, at volume fraction
// phi with ly = aspect l: between the planes y = 0 and y = ly (centres at least a radius inside),
// or periodic in y too. Random sequential addition in a dilated cell, then compression (in y
// alone between walls) with a soft repulsion. Reproducible for a given seed.
struct SpherePacking {
  std::vector<Space3> position;
  std::vector<double> radius;
  std::vector<int> species;
  double l = 0, ly = 0;
};
SpherePacking random_sphere_packing(std::int64_t n, MixRule mix, double size_ratio, double phi,
                                    double aspect, bool periodic_y, std::uint64_t seed);

// The l x aspect l x l cell random_sphere_packing fills at phi (its packing's l and ly equal
// these to round-off), without placing the spheres: what a scene plans before it is built.
struct SphereCell {
  double l = 0, ly = 0;
};
SphereCell sphere_packing_cell(std::int64_t n, MixRule mix, double size_ratio, double phi,
                               double aspect);

// The mobile particles of cfg: a random packing, or the configuration of particles.init_file
// (whose overlaps are judged across y too where the scene is periodic in y).
Packing initial_packing(const struct Config& cfg, bool periodic_y);

// Relax overlaps of discs in a cell periodic in x (and in y if periodic_y) by overdamped
// steepest descent on a harmonic repulsion; returns the largest remaining overlap.
double relax_overlaps(std::vector<Vec2>& position, const std::vector<double>& radius, double lx,
                      double ly, bool periodic_y, double tolerance, int max_iterations);

}  // namespace sheardiff
