// The profiles across the gap as their own observer (observe/profiles.hpp): composed only for
// scenes with walls, and its bins add up to the cell's own numbers (stresses, disc area).
#include <gtest/gtest.h>

#include <filesystem>
#include <numeric>

#include "sheardiff/observe/profiles.hpp"
#include "sheardiff/run.hpp"
#include "sheardiff/run_parts.hpp"

namespace sheardiff {
namespace {

Config cell_config(const std::string& scene) {
  Config cfg;
  cfg.scene.type = scene;
  cfg.particles.n = 60;
  cfg.particles.phi_init = 0.74;
  cfg.run.seed = 11;
  cfg.analysis.diffusion = false;
  return cfg;
}

int profile_observers(const Config& cfg) {
  int n = 0;
  for (const auto& o : make_observers(cfg, std::filesystem::temp_directory_path()))
    n += dynamic_cast<const ProfilesObserver*>(o.get()) != nullptr;
  return n;
}

TEST(ProfilesObserver, IsComposedForScenesWithWallsOnly) {
  for (const SceneKind& k : scene_registry())
    // The channel has its own profiles (observe/channel.hpp).
    EXPECT_EQ(profile_observers(cell_config(k.name)),
              k.periodic_y || !k.imposes_shear_rate() ? 0 : 1)
        << k.name;
  Config off = cell_config("pressure_shear");
  off.observables.profiles = false;
  EXPECT_EQ(profile_observers(off), 0);
}

// One measured step: the bins' stresses times their width add up to the cell's stress times the
// gap (every pair lands in one bin), and their disc area to the discs'.
TEST(ProfilesObserver, BinsAddUpToTheCell) {
  const Config cfg = cell_config("pressure_shear");
  Simulation sim(cfg);
  for (int k = 0; k < 300; ++k) sim.step();
  const Dynamics& d = sim.dynamics();
  ProfilesObserver profiles(cfg, [](const Dynamics&) { return true; });
  const StressSample s = sim.sample();
  profiles.on_step(StepView{d, sim.integrator().velocities(), s, 1.0});
  nlohmann::json js;
  profiles.finish(d, js, nullptr);
  ASSERT_TRUE(js.contains("profile_shear_stress"));
  const double bin = cfg.observables.profile_bin, h = d.height();
  const auto sum = [&](const char* key) {
    const auto v = js[key].get<std::vector<double>>();
    return std::accumulate(v.begin(), v.end(), 0.0) * bin;
  };
  EXPECT_NEAR(sum("profile_shear_stress"), s.shear_stress() * h,
              1e-10 * std::abs(s.pressure() * h));
  EXPECT_NEAR(sum("profile_pressure"), s.pressure() * h, 1e-10 * std::abs(s.pressure() * h));
  double area = 0.0;
  const Particles& p = d.particles();
  for (std::size_t i = 0; i < p.n_mobile; ++i) area += kPi * p.radius[i] * p.radius[i];
  EXPECT_NEAR(sum("profile_phi") * d.box().lx, area, 1e-9 * area);
  EXPECT_EQ(js["profile_y"].size(), js["profile_pressure"].size());
}

}  // namespace
}  // namespace sheardiff
