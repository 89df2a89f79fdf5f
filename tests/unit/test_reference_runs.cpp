// Behaviour pinned to the bit (issue 14, item 6): a fixed short run of each scene must end in
// exactly the state recorded here from main before the engine's restructuring (2026-12-01,
// commit "Reference runs"). Restructuring code must not change a single bit of the physics; a
// deliberate change of the physics updates these values in the same commit and says why.
//
// The runs use Eigen's simplicial Cholesky, not CHOLMOD: CHOLMOD's supernodal kernels come from
// OpenBLAS, which picks its kernels for the CPU at run time, so its last bits may differ
// between machines; the Eigen path depends only on this build.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstring>

#include "sheardiff/run.hpp"

namespace sheardiff {
namespace {

// FNV-1a over the bytes of the doubles: any change of any bit changes it.
std::uint64_t fnv1a(const std::vector<double>& v) {
  std::uint64_t h = 1469598103934665603ull;
  for (double x : v) {
    unsigned char b[sizeof(double)];
    std::memcpy(b, &x, sizeof(double));
    for (unsigned char c : b) h = (h ^ c) * 1099511628211ull;
  }
  return h;
}

struct Outcome {
  std::uint64_t positions = 0, velocities = 0;
  double strain = 0, shear_stress = 0, pressure = 0;
  long steps = 0;
};

// at_rest_first: the run's frame at step 0 solves at the configuration as it is before the first
// step (Simulation::solve_at_rest); the run must go on exactly as without it.
Outcome run(const std::string& scene, int steps, bool at_rest_first = false) {
  Config cfg;
  cfg.scene.type = scene;
  cfg.particles.n = 60;
  cfg.particles.phi_init = 0.74;
  cfg.run.seed = 11;
  cfg.run.strain = 100.0;
  cfg.flow.j = 1e-2;
  cfg.contact.ktilde = 1e4;
  cfg.solver.cholesky = "eigen";
  Simulation sim(cfg);
  if (at_rest_first) {
    EXPECT_TRUE(sim.solve_at_rest());
  }
  for (int k = 0; k < steps; ++k) EXPECT_TRUE(sim.try_step()) << scene << " step " << k;
  const Dynamics& d = sim.dynamics();
  std::vector<double> x, u;
  for (const Vec2& r : d.particles().position) x.insert(x.end(), {r.x(), r.y()});
  for (const Vec3& v : sim.integrator().velocities().u) u.insert(u.end(), {v.x(), v.y(), v.z()});
  const StressSample s = sim.sample();
  Outcome o{fnv1a(x), fnv1a(u), d.strain(), s.shear_stress(), s.pressure(), d.steps()};
  std::printf(
      "%s: %d contacts; positions %#llx velocities %#llx strain %.17g shear %.17g "
      "pressure %.17g\n",
      scene.c_str(), s.contacts, static_cast<unsigned long long>(o.positions),
      static_cast<unsigned long long>(o.velocities), o.strain, o.shear_stress, o.pressure);
  return o;
}

TEST(ReferenceRuns, SimpleShearIsBitIdenticalToTheRecordedRun) {
  const Outcome o = run("simple_shear", 400);
  EXPECT_EQ(o.positions, 0xb57559c4efa25d29ull);
  EXPECT_EQ(o.velocities, 0x70adc4b7c9334d17ull);
  EXPECT_EQ(o.strain, 0.17657650170605427);
  EXPECT_EQ(o.shear_stress, 0.43082492834501523);
  EXPECT_EQ(o.pressure, 0.49588972362181044);
}

TEST(ReferenceRuns, PressureShearIsBitIdenticalToTheRecordedRun) {
  const Outcome o = run("pressure_shear", 3000);  // past the wall's free fall: 65 contacts
  // Recorded again on 2026-12-05, twice: contacts with the floating wall that switch to sticking
  // are solved on the factor (low-rank terms and the wall's border) instead of a new
  // factorisation, and then A^-1 of the changed border is updated from the terms' Woodbury
  // columns instead of solved again: the same system rounded differently each time (strain,
  // stresses within 5e-13 relative).
  EXPECT_EQ(o.positions, 0xf30ce14e39d5ed3dull);
  EXPECT_EQ(o.velocities, 0x1df2c7323332330dull);
  EXPECT_EQ(o.strain, 0.70970149350101164);
  EXPECT_EQ(o.shear_stress, 0.36479319275920646);
  EXPECT_EQ(o.pressure, 0.74649563187203127);
}

TEST(ReferenceRuns, TheFrameAtRestLeavesTheRunsUnchanged) {
  for (const char* scene : {"simple_shear", "pressure_shear"}) {
    const int steps = std::string(scene) == "simple_shear" ? 400 : 3000;
    const Outcome a = run(scene, steps), b = run(scene, steps, true);
    EXPECT_EQ(a.positions, b.positions) << scene;
    EXPECT_EQ(a.velocities, b.velocities) << scene;
    EXPECT_EQ(a.strain, b.strain) << scene;
    EXPECT_EQ(a.shear_stress, b.shear_stress) << scene;
  }
}

}  // namespace
}  // namespace sheardiff
