// End-to-end simple shear: a 200-particle Lees-Edwards run over one strain with the default
// engine (implicit springs, adaptive step), and bitwise reproducibility for a given seed.
//
// Units of docs/model.md: d = 1, eta = 1, P = 1; strain = J t.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "sheardiff/run.hpp"

namespace sheardiff {
namespace {

Config shear_config() {
  Config cfg;  // defaults: simple_shear scene, area mix, size ratio 1.4, implicit, adaptive dt
  cfg.particles.n = 200;
  cfg.particles.phi_init = 0.70;
  cfg.run.strain = 1.0;
  cfg.flow.j = 1e-2;
  cfg.contact.ktilde = 1e4;
  cfg.integrator.type = IntegratorType::Implicit;
  return cfg;
}

TEST(SimpleShear, OneStrainResistsShearWithSmallOverlaps) {
  const Config cfg = shear_config();
  Simulation sim(cfg);
  const Dynamics& d = sim.dynamics();
  ASSERT_EQ(d.particles().n_mobile, 200u);
  ASSERT_TRUE(d.box().lees_edwards);
  EXPECT_DOUBLE_EQ(d.flow().gammadot, cfg.flow.j);

  int samples = 0, late_samples = 0;
  double late_sxy = 0.0, late_pressure = 0.0;
  StressSample last;
  while (d.strain() < cfg.run.strain) {
    ASSERT_LT(d.steps(), 200000) << "step size collapsed at strain " << d.strain();
    sim.step();
    if (d.steps() % 20 != 0) continue;
    last = sim.sample();
    ++samples;
    ASSERT_TRUE(std::isfinite(last.shear_stress()) && std::isfinite(last.pressure()))
        << "strain " << d.strain();
    // Overlaps stay small: with ktilde = 1e4 a contact force of f (in P d^2) overlaps f * 1e-4
    // d, so 5% of d would take a force of 500 P d^2, two orders of magnitude above the stress
    // scale of this flow (measured max overlap ~ 1e-3 d).
    EXPECT_LT(last.max_overlap, 0.05) << "strain " << d.strain();
    if (d.strain() >= 0.5) {  // past the start-up transient (contacts build up over ~0.1)
      late_sxy += last.shear_stress();
      late_pressure += last.pressure();
      ++late_samples;
    }
  }
  EXPECT_GE(d.strain(), cfg.run.strain);
  EXPECT_GT(samples, 10);
  ASSERT_GT(late_samples, 0);
  late_sxy /= late_samples;
  late_pressure /= late_samples;
  // The suspension resists shear: positive shear stress and pressure at the end of the run and
  // on average over the second half.
  EXPECT_GT(last.shear_stress(), 0.0);
  EXPECT_GT(last.pressure(), 0.0);
  EXPECT_GT(late_sxy, 0.0);
  EXPECT_GT(late_pressure, 0.0);
}

// Same seed, same build: the run is deterministic (sorted neighbour list, no threads), so the
// positions after 50 steps are bit-identical. Another seed gives another packing and run.
TEST(SimpleShear, SameSeedIsBitIdentical) {
  auto positions_after = [](std::int64_t seed) {
    Config cfg = shear_config();
    cfg.run.seed = seed;
    Simulation sim(cfg);
    for (int k = 0; k < 50; ++k) sim.step();
    EXPECT_EQ(sim.dynamics().steps(), 50);
    return sim.dynamics().particles().unwrapped;
  };
  const std::vector<Vec2> a = positions_after(1), b = positions_after(1), c = positions_after(2);
  ASSERT_EQ(a.size(), b.size());
  std::size_t identical = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].x() == b[i].x() && a[i].y() == b[i].y()) ++identical;
  EXPECT_EQ(identical, a.size());
  ASSERT_EQ(a.size(), c.size());
  double diff = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) diff = std::max(diff, (a[i] - c[i]).norm());
  // Different random packings: centres differ by O(d), far above any round-off.
  EXPECT_GT(diff, 0.1);
}

}  // namespace
}  // namespace sheardiff
