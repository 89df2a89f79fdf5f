// Lees-Edwards boundary conditions: a pair seen across the sheared y boundary behaves exactly
// like the same pair in the interior, and the neighbour list finds every image pair.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/core/box.hpp"
#include "sheardiff/neighbour/neighbour_list.hpp"
#include "sheardiff/run.hpp"
#include "sheardiff/scene/scene.hpp"
#include "sheardiff/setup/random_packing.hpp"

namespace sheardiff {
namespace {

constexpr double kLx = 12.0, kLy = 10.0, kGammadot = 0.1, kOffset = 3.7;
constexpr double kAi = 0.5, kAj = 0.7;  // top particle small, bottom particle large

Scene two_particle_scene(const Vec2& top, const Vec2& bottom, bool top_first, double offset) {
  Scene sc;
  sc.particles.resize(2);
  sc.particles.n_mobile = 2;
  const int t = top_first ? 0 : 1, b = 1 - t;
  sc.particles.position[t] = top;
  sc.particles.position[b] = bottom;
  sc.particles.radius[t] = kAi;
  sc.particles.radius[b] = kAj;
  sc.particles.species[b] = 1;
  sc.particles.unwrapped = sc.particles.position;
  sc.box.lx = kLx;
  sc.box.ly = kLy;
  sc.box.lees_edwards = true;
  sc.box.le_offset = offset;
  sc.flow = ImposedFlow{kGammadot, 0.0};
  return sc;
}

struct PairCase {
  double h;        // reduced gap of the pair (negative: contact)
  bool top_first;  // particle index order (decides whether the pair is seen with ky = +1 or -1)
};

class LeesEdwardsPair : public testing::TestWithParam<PairCase> {};

TEST_P(LeesEdwardsPair, AcrossTheBoundaryEqualsTheInteriorTwin) {
  const PairCase pc = GetParam();
  const double s = kAi + kAj, r = 0.5 * s * (2.0 + pc.h);
  const double dy = 0.7, dx = std::sqrt(r * r - dy * dy);
  // Lees-Edwards: top at y = 9.6, bottom at y = 0.3; the bottom one's image at +Ly sits at
  // x + le_offset (mod Lx), which is placed dx to the right of the top one.
  const Vec2 top_le(2.0, 9.6);
  Vec2 bottom_le(top_le.x() + dx - kOffset, 0.3);
  bottom_le.x() -= kLx * std::floor(bottom_le.x() / kLx);
  // The interior twin: same relative position, no boundary crossing, no offset involved.
  const Vec2 top_in(2.0, 4.6), bottom_in(2.0 + dx, 5.3);

  Config cfg;
  cfg.flow.j = kGammadot;
  Simulation le(cfg, two_particle_scene(top_le, bottom_le, pc.top_first, kOffset));
  Simulation in(cfg, two_particle_scene(top_in, bottom_in, pc.top_first, 0.0));

  // The neighbour list: exactly one pair, across the boundary with ky = +1 (seen from the
  // top particle) or -1 (seen from the bottom one), and inside the cell for the twin.
  const auto& pairs_le = le.dynamics().neighbours().pairs();
  const auto& pairs_in = in.dynamics().neighbours().pairs();
  ASSERT_EQ(pairs_le.size(), 1u);
  ASSERT_EQ(pairs_in.size(), 1u);
  EXPECT_EQ(pairs_le[0].i, 0);
  EXPECT_EQ(pairs_le[0].j, 1);
  EXPECT_EQ(pairs_le[0].ky, pc.top_first ? 1 : -1);
  EXPECT_EQ(pairs_in[0].ky, 0);
  EXPECT_EQ(pairs_in[0].kx, 0);
  const Box& box = le.dynamics().box();
  const Particles& p_le = le.dynamics().particles();
  const Vec2 rij =
      p_le.position[1] + box.image_shift(pairs_le[0].kx, pairs_le[0].ky) - p_le.position[0];
  EXPECT_NEAR(rij.norm(), r, 1e-12);

  // Solve both at the current configuration (the first step's implicit dt is irrelevant:
  // any dt > 0 is the same for both; 0.05 exercises dt K for the contact case).
  const double dt = 0.05;
  Velocities v_le, v_in;
  le.dynamics().begin_step();
  in.dynamics().begin_step();
  ASSERT_EQ(le.dynamics().neighbours().pairs()[0].history.touching, pc.h < 0.0);
  ASSERT_EQ(in.dynamics().neighbours().pairs()[0].history.touching, pc.h < 0.0);
  ASSERT_TRUE(le.dynamics().solve(dt, v_le));
  ASSERT_TRUE(in.dynamics().solve(dt, v_in));

  const PairTerm& t_le = le.dynamics().force_balance().terms()[0];
  const PairTerm& t_in = in.dynamics().force_balance().terms()[0];
  ASSERT_TRUE(t_le.on);
  EXPECT_NEAR(t_le.g.h, pc.h, 1e-12);
  EXPECT_NEAR(t_in.g.h, pc.h, 1e-12);
  // The image of the partner moves with the extra velocity +-gammadot Ly.
  EXPECT_NEAR(t_le.image_j.x(), (pc.top_first ? 1 : -1) * kGammadot * kLy, 1e-15);
  EXPECT_EQ(t_in.image_j.x(), 0.0);

  // Pair forces: the two configurations differ by a uniform translation of both discs and of
  // the flow (the positions differ by 5 in y, i.e. the flow by 0.5 in x), which lubrication
  // and springs do not see. Positions differ at 1e-15 from the different sums; lubrication
  // amplifies by at most 1/(h + delta) ~ 20, so 1e-10 relative is a generous bound.
  const Vec6 f_le = t_le.force(v_le.u[0], v_le.u[1]);
  const Vec6 f_in = t_in.force(v_in.u[0], v_in.u[1]);
  const double fscale = f_in.cwiseAbs().maxCoeff();
  ASSERT_GT(fscale, 1e-6) << "the pair must carry a force for the comparison to mean anything";
  EXPECT_LE((f_le - f_in).cwiseAbs().maxCoeff(), 1e-10 * fscale)
      << "LE force " << f_le.transpose() << "\ntwin force " << f_in.transpose();

  // Non-affine velocities U - U_inf of each particle (scale: gammadot d).
  const Particles& p_in = in.dynamics().particles();
  const ImposedFlow& flow = le.dynamics().flow();
  double na_scale = 0.0;
  for (int k = 0; k < 2; ++k) {
    const Vec3 na_le = v_le.u[k] - flow.velocity(p_le.position[k]);
    const Vec3 na_in = v_in.u[k] - flow.velocity(p_in.position[k]);
    na_scale = std::max(na_scale, na_in.cwiseAbs().maxCoeff());
    SCOPED_TRACE(testing::Message() << "particle " << k);
    EXPECT_LE((na_le - na_in).cwiseAbs().maxCoeff(), 1e-10 * kGammadot)
        << "LE " << na_le.transpose() << "\ntwin " << na_in.transpose();
  }
  EXPECT_GT(na_scale, 1e-6 * kGammadot) << "the pair must perturb the affine flow";

  // One full step each: same dt, same non-affine displacement, same tangential spring.
  le.step();
  in.step();
  EXPECT_NEAR(le.integrator().last_dt(), in.integrator().last_dt(),
              1e-10 * in.integrator().last_dt());
  const auto& q_le = le.dynamics().neighbours().pairs();
  const auto& q_in = in.dynamics().neighbours().pairs();
  ASSERT_EQ(q_le.size(), 1u);
  ASSERT_EQ(q_in.size(), 1u);
  EXPECT_EQ(q_le[0].history.touching, q_in[0].history.touching);
  EXPECT_NEAR(q_le[0].history.contact.xi, q_in[0].history.contact.xi,
              1e-10 * std::max(std::abs(q_in[0].history.contact.xi), 1e-12));
  if (pc.h < 0.0) {
    EXPECT_NE(q_in[0].history.contact.xi, 0.0) << "the contact should have stretched";
  }
  // The offset advanced by gammadot Ly dt.
  EXPECT_NEAR(le.dynamics().box().le_offset, kOffset + kGammadot * kLy * le.integrator().last_dt(),
              1e-12);
}

INSTANTIATE_TEST_SUITE_P(Gaps, LeesEdwardsPair,
                         testing::Values(PairCase{0.05, true}, PairCase{0.05, false},
                                         PairCase{-0.004, true}, PairCase{-0.004, false}),
                         [](const testing::TestParamInfo<PairCase>& info) {
                           return std::string(info.param.h < 0 ? "contact" : "gap") +
                                  (info.param.top_first ? "_top_first" : "_bottom_first");
                         });

// ---- Neighbour list against brute force ------------------------------------------------------

using PairKey = std::tuple<int, int, int, int>;  // i, j, kx, ky

std::set<PairKey> brute_force_pairs(const Particles& p, const Box& box, const NeighbourList& nl) {
  // Every image (kx, ky), ky in -1..1; kx over a range wide enough for any offset (the
  // offset is unwrapped, so kx of a ky = +-1 image can be far from 0).
  const int kmax = static_cast<int>(std::ceil(std::abs(box.le_offset) / box.lx)) + 2;
  std::set<PairKey> out;
  const int n = static_cast<int>(p.size());
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      const double rc = nl.cutoff(p.radius[i], p.radius[j]);
      for (int ky = -1; ky <= 1; ++ky)
        for (int kx = -kmax; kx <= kmax; ++kx) {
          const Vec2 d = p.position[j] + box.image_shift(kx, ky) - p.position[i];
          if (d.norm() <= rc) out.emplace(i, j, kx, ky);
        }
    }
  return out;
}

class NeighbourBruteForce : public testing::TestWithParam<double> {};

TEST_P(NeighbourBruteForce, ListEqualsAllImagePairsWithinCutoff) {
  const Packing pk = random_packing(400, MixRule::Area, 1.4, 0.7, 1.0, 17);
  Particles p;
  p.resize(pk.position.size());
  p.n_mobile = p.size();
  p.position = pk.position;
  p.unwrapped = pk.position;
  p.radius = pk.radius;
  p.species = pk.species;
  Box box;
  box.lx = pk.lx;
  box.ly = pk.ly;
  box.lees_edwards = true;
  box.le_offset = GetParam() * box.lx;
  // The default range of the engine: lubrication cut-off h_max = 0.5, skin 0.3.
  NeighbourList nl(1.25, 0.3);
  nl.rebuild(p, box);

  std::set<PairKey> listed;
  for (const Pair& pr : nl.pairs()) {
    EXPECT_TRUE(listed.emplace(pr.i, pr.j, pr.kx, pr.ky).second)
        << "duplicate pair " << pr.i << " " << pr.j;
    EXPECT_LT(pr.i, pr.j);
  }
  const std::set<PairKey> want = brute_force_pairs(p, box, nl);
  ASSERT_GT(want.size(), 400u);  // a dense packing: several neighbours per particle
  std::size_t across = 0;
  for (const PairKey& k : want) across += std::get<3>(k) != 0 ? 1 : 0;
  ASSERT_GT(across, 0u) << "the test needs pairs across the sheared boundary";

  std::vector<PairKey> missing, extra;
  std::set_difference(want.begin(), want.end(), listed.begin(), listed.end(),
                      std::back_inserter(missing));
  std::set_difference(listed.begin(), listed.end(), want.begin(), want.end(),
                      std::back_inserter(extra));
  EXPECT_TRUE(missing.empty()) << missing.size() << " pairs missing, e.g. ("
                               << (missing.empty() ? 0 : std::get<0>(missing[0])) << ", "
                               << (missing.empty() ? 0 : std::get<1>(missing[0])) << ", kx "
                               << (missing.empty() ? 0 : std::get<2>(missing[0])) << ", ky "
                               << (missing.empty() ? 0 : std::get<3>(missing[0])) << ")";
  EXPECT_TRUE(extra.empty()) << extra.size() << " pairs listed beyond the cut-off";
}

// Offsets as fractions of Lx: small, a generic value, just under Lx, negative and an unwrapped
// offset of several box lengths (le_offset grows as gammadot Ly t during a run).
INSTANTIATE_TEST_SUITE_P(Offsets, NeighbourBruteForce,
                         testing::Values(0.0, 0.21, 0.5, 0.97, -0.33, 3.62));

TEST(LeesEdwardsWrap, CrossingInYShiftsXByTheOffset) {
  // A particle at y = Ly + 0.2 is the +Ly image of one at y = 0.2 whose x is x - le_offset;
  // at y = -0.3 it is the -Ly image of one at Ly - 0.3 and x + le_offset (all mod Lx).
  Particles p;
  p.resize(2);
  p.n_mobile = 2;
  p.position = {Vec2(5.0, kLy + 0.2), Vec2(1.0, -0.3)};
  p.unwrapped = p.position;
  Box box;
  box.lx = kLx;
  box.ly = kLy;
  box.lees_edwards = true;
  box.le_offset = kOffset;
  NeighbourList nl(1.25, 0.3);
  nl.rebuild(p, box);
  EXPECT_NEAR(p.position[0].x(), 5.0 - kOffset, 1e-12);
  EXPECT_NEAR(p.position[0].y(), 0.2, 1e-12);
  EXPECT_NEAR(p.position[1].x(), 1.0 + kOffset, 1e-12);
  EXPECT_NEAR(p.position[1].y(), kLy - 0.3, 1e-12);
  // Unwrapped positions are left alone.
  EXPECT_EQ(p.unwrapped[0], Vec2(5.0, kLy + 0.2));
  // Image velocities: +gammadot Ly for the image above.
  const ImposedFlow flow{kGammadot, 0.0};
  EXPECT_DOUBLE_EQ(flow.image_velocity_x(1, box.ly), kGammadot * kLy);
  EXPECT_DOUBLE_EQ(flow.image_velocity_x(-1, box.ly), -kGammadot * kLy);
  const Vec2 shift = box.image_shift(-1, 1);
  EXPECT_DOUBLE_EQ(shift.x(), -kLx + kOffset);
  EXPECT_DOUBLE_EQ(shift.y(), kLy);
}

}  // namespace
}  // namespace sheardiff
