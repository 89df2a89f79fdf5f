// The worked examples of docs/extending.md, written outside the library against its interfaces
// alone: "An analyser" (an observer, driven by the engine's steps as the run's step loop drives
// the observers, checked against a closed form and through a checkpoint round trip) and
// "A scene" (a builder and the registry row that answers the run's questions).
#include <gtest/gtest.h>

#include <cmath>

#include "sheardiff/core/archive.hpp"
#include "sheardiff/engine.hpp"
#include "sheardiff/observe/observer.hpp"
#include "sheardiff/run_parts.hpp"
#include "sheardiff/scene/registry.hpp"
#include "sheardiff/scene/scene.hpp"

namespace sheardiff {
namespace {

// The mean spin of the mobile discs, time-averaged (weighted by the step) after a transient:
// in a shear flow a free disc turns with the fluid's vorticity, omega = -gammadot / 2.
class MeanSpinObserver final : public Observer {
 public:
  explicit MeanSpinObserver(double transient_strain) : transient_(transient_strain) {}
  std::vector<std::string> frame_names() const override { return {"mean_spin"}; }
  std::vector<std::string> frame_units() const override { return {"P/eta"}; }
  void on_frame(const StepView& v, std::vector<double>& values) override {
    values.push_back(spin(v));
  }
  void on_step(const StepView& v) override {
    if (v.dynamics.strain() <= transient_) return;
    weight_ += v.dt;
    sum_ += v.dt * spin(v);
  }
  void serialize(Archive& a) override {
    a.tag("mean_spin");
    a.io(weight_);
    a.io(sum_);
  }
  void finish(const Dynamics&, nlohmann::json& summary, H5mdWriter*) override {
    summary["mean_spin"] = weight_ > 0.0 ? sum_ / weight_ : std::nan("");
  }

 private:
  static double spin(const StepView& v) {
    const auto& p = v.dynamics.particles();
    double s = 0.0;
    for (std::size_t i = 0; i < p.n_mobile; ++i) s += v.velocities.u[i].z();
    return p.n_mobile ? s / static_cast<double>(p.n_mobile) : 0.0;
  }
  double transient_, weight_ = 0.0, sum_ = 0.0;
};

// The loop of src/run.cpp's StepLoop, reduced to what an observer sees.
void drive(Simulation& sim, Observer& o, int steps) {
  for (int k = 0; k < steps; ++k) {
    ASSERT_TRUE(sim.try_step());
    const StressSample s = sim.sample();
    o.on_step(
        StepView{sim.dynamics(), sim.integrator().velocities(), s, sim.integrator().last_dt()});
  }
}

Config dilute_shear() {
  Config c;
  c.scene.type = "simple_shear";
  // Three discs in a cell ~22 d wide: no pair is ever within the lubrication or contact range,
  // so each disc turns exactly with the fluid.
  c.particles.n = 3;
  c.particles.phi_init = 0.005;
  c.flow.j = 1e-2;
  c.run.seed = 3;
  c.run.strain = 10.0;
  return c;
}

TEST(ExtendingExample, AnAnalyserWrittenOutsideTheLibrary) {
  const Config cfg = dilute_shear();
  Simulation sim(cfg);
  MeanSpinObserver spin(0.05);
  drive(sim, spin, 400);
  nlohmann::json js;
  spin.finish(sim.dynamics(), js, nullptr);
  // Every disc free: the mean spin is the vorticity, -gammadot / 2 (gammadot = J P / eta here),
  // to the round-off of the solve.
  const double gammadot = sim.dynamics().flow().clock_rate();
  EXPECT_NEAR(js["mean_spin"].get<double>(), -0.5 * gammadot, 1e-9 * gammadot);
  // Its accumulators survive a checkpoint: a copy restored from the bytes finishes the same.
  Archive w = Archive::writer();
  spin.serialize(w);
  MeanSpinObserver restored(0.05);
  Archive r = Archive::reader(w.bytes());
  restored.serialize(r);
  nlohmann::json again;
  restored.finish(sim.dynamics(), again, nullptr);
  EXPECT_EQ(again, js);
}

// ---- A scene ----------------------------------------------------------------------------------

// Two discs on one streamline of a Lees-Edwards cell, far apart: each is carried by the imposed
// flow at the velocity of its centre and turns with the fluid, whatever the cell.
Scene build_streamline_pair(const Config& cfg) {
  Scene sc;
  sc.particles.resize(2);
  sc.particles.n_mobile = 2;
  sc.particles.position = {Vec2(4.0, 7.0), Vec2(16.0, 7.0)};
  sc.particles.unwrapped = sc.particles.position;
  sc.box.lx = 24.0;
  sc.box.ly = 20.0;
  sc.box.lees_edwards = true;
  sc.flow.gammadot = cfg.flow.j;
  sc.flow.y0 = 0.0;
  return sc;
}

// The row src/scene/registry.cpp would list (one line there registers the name): a sheared
// scene measured after run.transient_strain, so a run composes the rheology and the shear
// analyses for it.
const SceneKind kStreamlinePair{.name = "streamline_pair",
                                .doc = "`streamline_pair` = two distant discs on one streamline",
                                .build = build_streamline_pair,
                                .periodic_y = true,
                                .measures = Measures::ShearAfterTransient};

TEST(ExtendingExample, ASceneWrittenOutsideTheLibrary) {
  // Not registered, so scene.type does not name it ...
  EXPECT_THROW(scene_kind(kStreamlinePair.name), ConfigError);
  // ... but the engine and the observers take it from its row as a run takes a registered one.
  Config cfg = dilute_shear();
  Simulation sim(cfg, kStreamlinePair.build(cfg));
  cfg.analysis.diffusion = false;  // two discs: nothing to average a diffusion over
  ObserverList observers = make_observers(kStreamlinePair, cfg, {});
  ASSERT_EQ(observers.size(), 1u);  // rheology; periodic in y, so no profiles across a gap
  observers.push_back(std::make_unique<MeanSpinObserver>(0.05));
  for (int k = 0; k < 200; ++k) {
    ASSERT_TRUE(sim.try_step());
    const StressSample s = sim.sample();
    const StepView v{sim.dynamics(), sim.integrator().velocities(), s, sim.integrator().last_dt()};
    for (auto& o : observers) o->on_step(v);
  }
  // Closed form: u_x = gammadot (y - y0), u_y = 0 and omega = -gammadot / 2 for each disc (the
  // pair is 12 d apart, far beyond the lubrication range), to the round-off of the solve.
  const double gammadot = sim.dynamics().flow().clock_rate();
  const auto& p = sim.dynamics().particles();
  const auto& u = sim.integrator().velocities().u;
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_NEAR(u[i].x(), gammadot * p.position[i].y(), 1e-9 * gammadot) << i;
    EXPECT_NEAR(u[i].y(), 0.0, 1e-9 * gammadot) << i;
    EXPECT_NEAR(u[i].z(), -0.5 * gammadot, 1e-9 * gammadot) << i;
  }
  nlohmann::json js;
  for (auto& o : observers) o->finish(sim.dynamics(), js, nullptr);
  EXPECT_NEAR(js["mean_spin"].get<double>(), -0.5 * gammadot, 1e-9 * gammadot);
  EXPECT_TRUE(js.contains("shear_stress"));
}

}  // namespace
}  // namespace sheardiff
