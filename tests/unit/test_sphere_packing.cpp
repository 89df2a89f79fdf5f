// The random start of spheres (setup/sphere_packing.cpp, particles.phi_init_spheres): the volume
// fraction asked for, no overlaps beyond the relaxation's tolerance (between spheres, across
// the periodic x and z, and against the walls), reproducible per seed, and the pressure cell
// of spheres built on it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sheardiff/config.hpp"
#include "sheardiff/scene/scene.hpp"
#include "sheardiff/setup/random_packing.hpp"

namespace sheardiff {
namespace {

// Largest overlap between any two spheres, every pair by minimum image in x and z (and in y over
// periodic_ly if positive) (O(N^2): an independent check of the cell grid that the packing
// uses).
double largest_overlap(const std::vector<Space3>& x, const std::vector<double>& r, double l,
                       std::size_t n, double periodic_ly = 0.0) {
  double worst = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      Space3 d = x[j] - x[i];
      d.x() -= l * std::round(d.x() / l);
      d.z() -= l * std::round(d.z() / l);
      if (periodic_ly > 0.0) d.y() -= periodic_ly * std::round(d.y() / periodic_ly);
      worst = std::max(worst, r[i] + r[j] - d.norm());
    }
  return worst;
}

TEST(SpherePacking, VolumeFractionNoOverlapsInsideTheWalls) {
  for (const double phi : {0.3, 0.5}) {
    const SpherePacking pk = random_sphere_packing(400, MixRule::Volume, 1.4, phi, 2.0, false, 7);
    ASSERT_EQ(pk.position.size(), 400u);
    double volume = 0.0;
    for (double a : pk.radius) volume += 4.0 / 3.0 * kPi * a * a * a;
    EXPECT_NEAR(volume / (pk.l * pk.l * pk.ly), phi, 1e-12) << phi;
    EXPECT_NEAR(pk.ly / pk.l, 2.0, 1e-12);
    // Equal volume of d and 1.4 d spheres: 400 / (1 + 1.4^3) = 106.8 large ones.
    EXPECT_EQ(std::count(pk.species.begin(), pk.species.end(), 1), 107);
    for (std::size_t i = 0; i < pk.position.size(); ++i) {
      const double a = pk.radius[i], y = pk.position[i].y();
      ASSERT_GE(y, a - 1e-12) << i;
      ASSERT_LE(y, pk.ly - a + 1e-12) << i;
      ASSERT_GE(pk.position[i].x(), 0.0);
      ASSERT_LT(pk.position[i].x(), pk.l);
      ASSERT_GE(pk.position[i].z(), 0.0);
      ASSERT_LT(pk.position[i].z(), pk.l);
    }
    // Sequential addition places without overlap; the compression leaves the relaxation's
    // tolerance of 1e-4 d (a contact of ktilde = 1e4 carries 1e-4 d at the pressure P).
    EXPECT_LT(largest_overlap(pk.position, pk.radius, pk.l, pk.position.size()), 1e-4) << phi;
  }
}

TEST(SpherePacking, PeriodicCellForSimpleShear) {
  // Periodic in y too (simple shear of spheres): compressed in every direction, so the cell
  // keeps its aspect, and no overlap across any periodic face.
  const SpherePacking pk = random_sphere_packing(300, MixRule::Volume, 1.4, 0.5, 1.0, true, 5);
  double volume = 0.0;
  for (double a : pk.radius) volume += 4.0 / 3.0 * kPi * a * a * a;
  EXPECT_NEAR(volume / (pk.l * pk.l * pk.ly), 0.5, 1e-12);
  EXPECT_NEAR(pk.ly, pk.l, 1e-12);
  for (const Space3& x : pk.position) {
    ASSERT_GE(x.minCoeff(), 0.0);
    ASSERT_LT(x.x(), pk.l);
    ASSERT_LT(x.y(), pk.ly);
    ASSERT_LT(x.z(), pk.l);
  }
  EXPECT_LT(largest_overlap(pk.position, pk.radius, pk.l, pk.position.size(), pk.ly), 1e-4);
}

TEST(SpherePacking, SpreadAcrossTheGap) {
  // Not a lattice and not piled at one wall: each third of the height holds about a third of
  // the volume (a random packing of 1000 spheres: within 0.1 of it).
  const SpherePacking pk = random_sphere_packing(1000, MixRule::Volume, 1.4, 0.45, 1.0, false, 3);
  double third[3] = {0, 0, 0}, all = 0;
  for (std::size_t i = 0; i < pk.position.size(); ++i) {
    const double v = std::pow(pk.radius[i], 3);
    third[std::min(2, static_cast<int>(3.0 * pk.position[i].y() / pk.ly))] += v;
    all += v;
  }
  for (double t : third) EXPECT_NEAR(t / all, 1.0 / 3.0, 0.1);
}

TEST(SpherePacking, ReproduciblePerSeed) {
  const auto a = random_sphere_packing(200, MixRule::Volume, 1.4, 0.45, 1.0, false, 11);
  const auto b = random_sphere_packing(200, MixRule::Volume, 1.4, 0.45, 1.0, false, 11);
  const auto c = random_sphere_packing(200, MixRule::Volume, 1.4, 0.45, 1.0, false, 12);
  EXPECT_EQ(a.position, b.position);
  EXPECT_NE(a.position, c.position);
}

TEST(SpherePacking, PressureCellOfSpheresStartsFromIt) {
  Config cfg;
  cfg.scene.dimension = 3;
  cfg.particles.n = 300;
  cfg.particles.phi_init_spheres = 0.5;
  const Scene3 sc = build_pressure_shear_3d(cfg);
  const Particles3& p = sc.particles;
  ASSERT_EQ(p.n_mobile, 300u);
  // The planned cell (checked before any work) is the built one.
  const PlannedCell planned = pressure_shear_3d_cell(cfg);
  EXPECT_NEAR(planned.lx, sc.box.lx, 1e-12);
  EXPECT_NEAR(planned.lz, sc.box.lz, 1e-12);
  // Between the walls' surfaces: the volume fraction asked for, and no sphere overlapping a
  // wall's sphere.
  double volume = 0.0;
  for (std::size_t i = 0; i < p.n_mobile; ++i) volume += kPi / 6.0 * std::pow(2 * p.radius[i], 3);
  EXPECT_NEAR(volume / (sc.box.lx * sc.box.lz * planned.ly), 0.5, 1e-12);
  EXPECT_LT(largest_overlap(p.position, p.radius, sc.box.lx, p.size()), 1e-4);
}

}  // namespace
}  // namespace sheardiff
