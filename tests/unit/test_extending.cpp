// The worked example of docs/extending.md, "An analyser": a new observer written outside the
// library against the Observer interface alone, driven by the engine's steps as the run's step
// loop drives the observers, checked against a closed form and through a checkpoint round trip.
#include <gtest/gtest.h>

#include <cmath>

#include "sheardiff/core/archive.hpp"
#include "sheardiff/engine.hpp"
#include "sheardiff/observe/observer.hpp"

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

}  // namespace
}  // namespace sheardiff
