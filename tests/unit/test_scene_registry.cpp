// The scene registry (src/scene/registry.cpp) and what walls do (core/walls.hpp): every row
// builds its scene, scene.type accepts exactly the registry's names, and a top wall that is
// driven but not floating moves with the imposed flow at its height and keeps the gap.
#include <gtest/gtest.h>

#include <string>

#include "sheardiff/run.hpp"

namespace sheardiff {
namespace {

Config small(const std::string& scene) {
  Config cfg;
  cfg.scene.type = scene;
  cfg.particles.n = 60;
  cfg.particles.phi_init = 0.7;
  cfg.run.seed = 3;
  return cfg;
}

TEST(SceneRegistry, EveryRowBuildsItsSceneAndIsAValidSceneType) {
  ASSERT_FALSE(scene_registry().empty());
  EXPECT_EQ(Config{}.scene.type, scene_registry().front().name);
  for (const SceneKind& k : scene_registry()) {
    EXPECT_EQ(&scene_kind(k.name), &k);
    const Scene sc = build_scene(small(k.name));
    EXPECT_EQ(sc.walls.has_value(), !k.periodic_y) << k.name;
    EXPECT_EQ(sc.box.lees_edwards, k.periodic_y) << k.name;
    // The channel's disc count follows from its areal fraction, width and wall row.
    const ChannelParams ch;
    const auto n = !k.imposes_shear_rate() ? static_cast<std::size_t>(std::llround(
                                                 ch.phi * 2.0 * ch.wall_discs * ch.h_over_a / kPi))
                                           : 60u;
    EXPECT_EQ(sc.particles.n_mobile, n) << k.name;
    const std::string needs = !k.imposes_shear_rate()
                                  ? "[particles]\nsize_ratio = 1.0\n[analysis]\ndiffusion = false\n"
                                  : "";
    const Config c =
        parse_config("[scene]\ntype = \"" + std::string(k.name) + "\"\n" + needs, "t.toml");
    EXPECT_EQ(c.scene.type, k.name);
  }
  EXPECT_THROW(scene_kind("channel_of_dreams"), ConfigError);
  try {
    parse_config("[scene]\ntype = \"channel_of_dreams\"\n", "t.toml");
    ADD_FAILURE() << "an unknown scene was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.type"), std::string::npos) << e.what();
  }
}

TEST(Walls, ADrivenTopWallMovesWithTheFlowAndKeepsTheGap) {
  Config cfg = small("pressure_shear");
  Scene sc = build_scene(cfg);
  ASSERT_TRUE(sc.walls);
  sc.walls->top_role = WallRole::Driven;
  for (int t : sc.walls->top) sc.particles.motion[static_cast<std::size_t>(t)] = Motion::DrivenWall;
  const int top = sc.walls->top.front();
  const Vec2 x0 = sc.particles.position[static_cast<std::size_t>(top)];
  Simulation sim(cfg, std::move(sc));
  const double h0 = sim.dynamics().height();
  for (int k = 0; k < 200; ++k) sim.step();
  const Dynamics& d = sim.dynamics();
  EXPECT_EQ(d.height(), h0);
  const Vec2 x = d.particles().unwrapped[static_cast<std::size_t>(top)];
  EXPECT_EQ(x.y(), x0.y());
  // The flow's velocity at the wall's centre line, v = gammadot (H + y0 - y0), for the whole run.
  const double vx = d.flow().velocity(Vec2(0.0, mean_height(d.particles(), d.walls()->top))).x();
  EXPECT_NEAR(vx, cfg.flow.j * h0, 1e-12);
  EXPECT_NEAR(x.x() - x0.x(), vx * d.time(), 1e-9 * vx * d.time());
}

}  // namespace
}  // namespace sheardiff
