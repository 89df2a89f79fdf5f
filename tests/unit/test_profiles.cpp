// The profiles across the gap as their own observer (observe/profiles.hpp): composed only for
// scenes with walls, and its bins add up to the cell's own numbers (stresses, disc area).
#include <gtest/gtest.h>

#include <filesystem>
#include <numeric>

#include "sheardiff/core/archive.hpp"
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
// gap (every pair lands in one bin), and their disc area to the discs'. With Heun the cell's
// stress is the mean of its two stages' (each stage's pair terms with its own velocities); the
// bins once took the corrector's terms with the mean velocities, which balance nothing.
class BinsAddUpToTheCell : public testing::TestWithParam<IntegratorType> {};
TEST_P(BinsAddUpToTheCell, ForEachIntegrator) {
  Config cfg = cell_config("pressure_shear");
  cfg.integrator.type = GetParam();
  Simulation sim(cfg);
  for (int k = 0; k < 300; ++k) sim.step();
  const Dynamics& d = sim.dynamics();
  ProfilesObserver profiles(cfg, [](const Dynamics&) { return true; });
  const StressSample s = sim.sample();
  profiles.on_step(StepView{d, sim.integrator().velocities(), s, 1.0, sim.integrator().stages(d)});
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
  if (GetParam() != IntegratorType::Heun) return;
  // The old way, the last solve's terms with the mean velocities, misses the cell's stress by
  // far more than round-off: the check above tells the two apart.
  ProfilesObserver old_way(cfg, [](const Dynamics&) { return true; });
  old_way.on_step(StepView{d,
                           sim.integrator().velocities(),
                           s,
                           1.0,
                           {{&d.force_balance().terms(), &sim.integrator().velocities(), 1.0}}});
  nlohmann::json old_js;
  old_way.finish(d, old_js, nullptr);
  const auto v = old_js["profile_pressure"].get<std::vector<double>>();
  EXPECT_GT(std::abs(std::accumulate(v.begin(), v.end(), 0.0) * bin - s.pressure() * h),
            1e-6 * std::abs(s.pressure() * h));
}
INSTANTIATE_TEST_SUITE_P(ProfilesObserver, BinsAddUpToTheCell,
                         testing::Values(IntegratorType::Implicit, IntegratorType::Heun),
                         [](const auto& info) { return to_string(info.param); });

// The lubrication part of the profiles' stresses, after `steps` steps of cfg: its bins add up to
// the stress of every pair's lubrication force, recomputed here from the law's coefficients and
// the solved velocities, and it is not the whole stress (the contacts carry some). Returns the
// summary.
template <class D>
nlohmann::json expect_lubrication_part(const Config& cfg, int steps) {
  SimulationOf<D> sim(cfg);
  for (int k = 0; k < steps; ++k) sim.step();
  const auto& d = sim.dynamics();
  const auto& v = sim.integrator().velocities();
  ProfilesObserverOf<D> profiles(cfg, [](const DynamicsOf<D>&) { return true; });
  const StressSample s = sim.sample();
  profiles.on_step(StepViewOf<D>{d, v, s, 1.0, sim.integrator().stages(d)});
  nlohmann::json js;
  profiles.finish(d, js, nullptr);
  const Lubrication& law = *d.force_balance().lubrication();
  const auto& pairs = d.neighbours().pairs();
  const auto& terms = d.force_balance().terms();
  double sxy = 0.0;
  int lubricated = 0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto& t = terms[k];
    const auto& pr = pairs[k];
    if (!t.on || !(pr.history.touching || t.g.h < cfg.lubrication.h_max)) continue;
    ++lubricated;
    const PairResistance r = law.coefficients(t.g.ai, t.g.aj, t.g.h);
    typename D::PairMatrix m;
    if constexpr (D::space == 2)
      m = r.matrix(t.g.n, t.g.t);
    else
      m = r.matrix_3d(t.g.n);
    typename D::PairVector u;
    u << v.u[pr.i], v.u[pr.j] + t.image_j;
    const typename D::Point fj = -(m * u).template segment<D::space>(D::body);
    const double l = pr.history.touching ? t.g.r : t.g.s;
    sxy -= 0.5 * l * (t.g.n.x() * fj.y() + t.g.n.y() * fj.x());
  }
  sxy /= horizontal_area(d, cfg.flow.lz);
  const double bin = cfg.observables.profile_bin;
  const auto sum = [&](const char* key) {
    const auto vals = js[key].get<std::vector<double>>();
    return std::accumulate(vals.begin(), vals.end(), 0.0) * bin;
  };
  EXPECT_GT(lubricated, 10);
  EXPECT_GT(s.contacts, 0);
  EXPECT_NEAR(sum("profile_shear_stress_lubrication"), sxy, 1e-10 * std::abs(s.pressure()));
  // The contacts' part, the rest, is a sizeable share: the test tells the two apart.
  const double total = sum("profile_shear_stress");
  EXPECT_GT(std::abs(total - sxy), 0.05 * std::abs(total));
  EXPECT_EQ(js["profile_pressure_lubrication"].size(), js["profile_pressure"].size());
  return js;
}

TEST(ProfilesObserver, LubricationPartOfTheStressOfDiscs) {
  expect_lubrication_part<Dim2>(cell_config("pressure_shear"), 300);
}

TEST(ProfilesObserver, LubricationPartOfTheStressOfSpheres) {
  Config cfg = cell_config("pressure_shear");
  cfg.scene.dimension = 3;
  cfg.particles.n = 64;
  cfg.particles.phi_init_spheres = 0.5;  // dense enough for contacts from the start
  cfg.contact.ktilde = 1e3;
  expect_lubrication_part<Dim3>(cfg, 100);
}

// The same for spheres: the bins' stresses add up to the cell's (Lx Lz bin volumes, the trace
// over 3), and their volume fractions to the mobile spheres' volume over Lx Lz (each sphere's
// caps cut exactly by the bin planes).
TEST(ProfilesObserver, SpheresBinsAddUpToTheCell) {
  Config cfg = cell_config("pressure_shear");
  cfg.scene.dimension = 3;
  cfg.particles.n = 64;
  cfg.particles.phi_init_spheres = 0.5;
  cfg.contact.ktilde = 1e3;
  Simulation3 sim(cfg);
  for (int k = 0; k < 100; ++k) sim.step();
  const Dynamics3& d = sim.dynamics();
  ProfilesObserverOf<Dim3> profiles(cfg, [](const Dynamics3&) { return true; });
  const StressSample s = sim.sample();
  profiles.on_step(
      StepViewOf<Dim3>{d, sim.integrator().velocities(), s, 1.0, sim.integrator().stages(d)});
  nlohmann::json js;
  profiles.finish(d, js, nullptr);
  const double bin = cfg.observables.profile_bin, h = d.height();
  const auto sum = [&](const char* key) {
    const auto v = js[key].get<std::vector<double>>();
    return std::accumulate(v.begin(), v.end(), 0.0) * bin;
  };
  ASSERT_TRUE(s.spheres);
  EXPECT_NEAR(sum("profile_shear_stress"), s.shear_stress() * h,
              1e-10 * std::abs(s.pressure() * h));
  EXPECT_NEAR(sum("profile_pressure"), s.pressure() * h, 1e-10 * std::abs(s.pressure() * h));
  double volume = 0.0;
  const auto& p = d.particles();
  for (std::size_t i = 0; i < p.n_mobile; ++i) volume += 4.0 / 3.0 * kPi * std::pow(p.radius[i], 3);
  EXPECT_NEAR(sum("profile_phi") * d.box().lx * d.box().lz, volume, 1e-9 * volume);
}

// Without lubrication there is no lubrication part to report.
TEST(ProfilesObserver, NoLubricationPartWithoutLubrication) {
  Config cfg = cell_config("pressure_shear");
  cfg.lubrication.enabled = false;
  Simulation sim(cfg);
  for (int k = 0; k < 50; ++k) sim.step();
  ProfilesObserver profiles(cfg, [](const Dynamics&) { return true; });
  profiles.on_step(StepView{sim.dynamics(), sim.integrator().velocities(), sim.sample(), 1.0,
                            sim.integrator().stages(sim.dynamics())});
  nlohmann::json js;
  profiles.finish(sim.dynamics(), js, nullptr);
  EXPECT_TRUE(js.contains("profile_shear_stress"));
  EXPECT_FALSE(js.contains("profile_shear_stress_lubrication"));
}

// A checkpoint of layout 8 kept no lubrication part: resumed before the window began, the part
// covers the window; resumed inside it, it would cover only the rest, so none is reported. A
// layout-9 checkpoint keeps it.
TEST(ProfilesObserver, LubricationPartOnlyOverTheWholeWindow) {
  Simulation sim(cell_config("pressure_shear"));
  sim.step();
  const Dynamics& d = sim.dynamics();
  const Velocities& v = sim.integrator().velocities();
  const auto one_step = [&](GapProfiles& g) {
    g.add(d.particles(), v.u, 0.0, d.height(), d.box().lx, 1.0);
    g.add_stress(d, sim.integrator().stages(d), 0.0, 1.0, 1.0);
  };
  const auto reported_after_resume = [&](Archive reader) {
    GapProfiles g(0.5);
    g.serialize(reader);
    one_step(g);
    nlohmann::json js;
    g.to_summary(js, 1.0, d.height(), 3.0);
    EXPECT_TRUE(js.contains("profile_shear_stress"));
    return js.contains("profile_shear_stress_lubrication");
  };
  // What layout 8 wrote: the section and the eight accumulators, empty before the window.
  const auto layout8 = [](std::size_t bins) {
    Archive a = Archive::writer();
    double section = 1.0;
    a.io(section);
    std::vector<double> acc(bins, 1.0);
    for (int k = 0; k < 8; ++k) a.io(acc);
    return Archive::reader(a.bytes(), 8);
  };
  EXPECT_TRUE(reported_after_resume(layout8(0)));
  EXPECT_FALSE(reported_after_resume(layout8(4)));
  GapProfiles begun(0.5);
  one_step(begun);
  Archive now = Archive::writer();
  begun.serialize(now);
  EXPECT_TRUE(reported_after_resume(Archive::reader(now.bytes())));
}

}  // namespace
}  // namespace sheardiff
