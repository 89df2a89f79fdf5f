// The implicit integrator at the stiff, slow corner of the issue-5 grid (ktilde = 1e5,
// J = 1e-4), with a fixed step 100 times the explicit stability limit: the step count there
// must come from accuracy, so the linearly implicit springs have to stay stable and keep the
// overlaps at the size the load sets, P d / kn times a force-chain factor.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sheardiff/run.hpp"

namespace sheardiff {
namespace {

TEST(ImplicitStiff, StableAtHundredTimesTheExplicitLimit) {
  Config c;
  c.scene.type = "pressure_shear";
  c.particles.n = 80;
  c.particles.phi_init = 0.75;
  c.flow.j = 1e-4;
  c.contact.ktilde = 1e5;
  c.run.seed = 2;
  c.integrator.type = IntegratorType::Implicit;
  const double dt_stab = explicit_stability_dt(c);
  c.integrator.dt = 100.0 * dt_stab;
  // dt_stab = 2 min(R_n / kn, R_t / kt): the tangential spring against the shear dashpot
  // (R_t ~ 7.2 + shared drag, kt = kn / 2) binds, ~3.3e-4 eta/P here; the step is ~0.03 eta/P.
  ASSERT_GT(dt_stab, 1e-4);
  ASSERT_LT(dt_stab, 1e-3);
  Simulation sim(c);
  const Dynamics& d = sim.dynamics();
  double max_overlap = 0.0;
  int loaded = 0;
  for (int k = 0; k < 1500; ++k) {
    sim.step();
    const StressSample s = sim.sample();
    ASSERT_TRUE(std::isfinite(s.max_overlap) && std::isfinite(s.top_wall_fx) &&
                std::isfinite(s.top_wall_fy))
        << "step " << k;
    for (std::size_t i = 0; i < d.particles().size(); ++i)
      ASSERT_TRUE(d.particles().position[i].allFinite()) << "step " << k;
    if (!sim.integrator().velocities().wall_free_fall) ++loaded;
    // The first steps land the top wall, falling at walls.free_fall_speed, onto the packing:
    // that impact (0.5 P d / eta x dt ~ 0.02 d per step) is not the contact mechanics tested.
    if (k >= 200) max_overlap = std::max(max_overlap, s.max_overlap);
  }
  // The packing carries the wall for most of the run (the test is not of a free fall).
  EXPECT_GT(loaded, 1000);
  EXPECT_GT(max_overlap, 0.0);
  // A contact's overlap is its normal force over kn. The wall load P Lx lz (Lx ~ 9 d) goes
  // through a few force chains, and the stress fluctuations of a slow dense flow put the largest
  // contact force of a step at tens of P d^2: measured typical max overlap ~ 10 P d / kn, peaks
  // 68 P d / kn over steps 200-1500. Bound: 150 P d / kn = 1.5e-3 d (a tenth of delta's scale
  // of the gap is 1e-3 d; an unstable integrator overlaps by O(0.1 d) within a few steps).
  EXPECT_LT(max_overlap, 150.0 / c.contact.ktilde) << "max overlap " << max_overlap;
}

}  // namespace
}  // namespace sheardiff
