// The worked examples of docs/extending.md, written outside the library against its interfaces
// alone: "An analyser" (an observer, driven by the engine's steps as the run's step loop drives
// the observers, checked against a closed form and through a checkpoint round trip) and
// "A scene" (a builder and the registry row that answers the run's questions) and "A pair law"
// (a law and its parameters, in the generic law set the pair loop is instantiated for).
#include <gtest/gtest.h>

#include <cmath>

#include "sheardiff/core/archive.hpp"
#include "sheardiff/engine.hpp"
#include "sheardiff/interactions/pair_laws.hpp"
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
    o.on_step(StepView{sim.dynamics(), sim.integrator().velocities(), s, sim.integrator().last_dt(),
                       sim.integrator().stages(sim.dynamics())});
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
    const StepView v{sim.dynamics(), sim.integrator().velocities(), s, sim.integrator().last_dt(),
                     sim.integrator().stages(sim.dynamics())};
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

// ---- A pair law -------------------------------------------------------------------------------

// A soft corona of thickness w around each disc: a central spring F = k (s + w - r) while the
// coronas overlap (s = a_i + a_j). Its parameters and keys, declared once (NAME_params.hpp) ...
struct CoronaParams {
  double k = 0.0;       // P d; 0 = off
  double width = 0.05;  // d

  template <class Keys>
  static void declare(Keys& keys) {
    keys.real("corona.k", &CoronaParams::k, 0.0, 1e6, false, "P d",
              "Stiffness of the coronas' central spring; 0 = off.");
    keys.real("corona.width", &CoronaParams::width, 0.0, 0.5, true, "d",
              "Thickness of each disc's corona.");
  }
};

// ... and the law (NAME.hpp): the contract of interactions/pair_law.hpp.
struct Corona {
  using History = NoHistory;
  double k = 0.0, width = 0.05;

  static std::optional<Corona> from(const CoronaParams& p) {
    if (!(p.k > 0.0)) return std::nullopt;
    return Corona{p.k, p.width};
  }
  double range_factor() const { return 1.0 + width; }  // the smallest pair has s = d
  bool acts(const PairGeometry& g, bool) const { return g.r < g.s + width; }
  void add_block(const PairGeometry& g, const History&, bool, double dt_implicit,
                 PairBlock& b) const {
    const Vec6 m = normal_mode(g);
    b.add_force(-k * (g.s + width - g.r) * m);
    // Over a step the centres approach by dt m.U: the force grows by k dt m.U.
    if (dt_implicit > 0.0) b.add_matrix(dt_implicit * k * m * m.transpose());
  }
  bool resistive() const { return false; }
  bool keeps_history() const { return false; }
  void advance(History&, const PairGeometry&, const Vec6&, double) const {}
  void cap(History&, const PairGeometry&) const {}
  void add_stability(double, StabilityTerms& t) const { t.normal_stiffness += k; }
  bool needs_rotations() const { return false; }
};

// What the schema's section adapter (src/config.cpp) reads from declare: here only recorded.
struct RecordedKeys {
  std::vector<std::string> names;
  std::vector<std::pair<double, double>> ranges;
  void real(std::string key, double CoronaParams::*, double lo, double hi, bool, std::string,
            std::string) {
    names.push_back(std::move(key));
    ranges.emplace_back(lo, hi);
  }
};

TEST(ExtendingExample, APairLawWrittenOutsideTheLibrary) {
  RecordedKeys keys;
  CoronaParams::declare(keys);
  EXPECT_EQ(keys.names, (std::vector<std::string>{"corona.k", "corona.width"}));
  EXPECT_FALSE(Corona::from(CoronaParams{}).has_value()) << "off by default: nothing computed";

  // The engine's laws with the corona added, as `using PairLaws = PairLawSet<...>` would list it;
  // lubrication and contacts off, so every number below is the corona's.
  const CoronaParams p{.k = 100.0, .width = 0.05};
  const PairLawSet<Lubrication, FrictionalContact, Corona> laws(std::nullopt, std::nullopt,
                                                                Corona::from(p));
  EXPECT_DOUBLE_EQ(laws.range_factor(), 1.05);  // the neighbour list's cut-off follows it
  EXPECT_FALSE(laws.needs_rotations());
  // Explicit stability limit 2 R / k, R the drag of two discs of radius 1/2 in series,
  // 3 pi eta d / 2, shared among the contacts of a disc in the densest packing (5, docs/model.md
  // section 7): the corona adds stiffness and no damping.
  EXPECT_NEAR(laws.explicit_stability_dt(2), 2.0 * (3.0 * kPi / 2.0 / 5.0) / 100.0, 1e-12);

  // Two small discs with coronas overlapping by 0.02 d: the pair's force is k 0.02 along the line
  // of centres, pushing them apart, and the implicit block is dt k m m^T.
  const PairGeometry g = PairGeometry::make(Vec2(1.03, 0.0), 0.5, 0.5);
  const PairHistory none;
  Mat6 m = Mat6::Constant(7.0);
  Vec6 f = Vec6::Constant(7.0);
  bool sliding = true;
  ASSERT_TRUE(laws.add_blocks(g, none, 0.01, m, f, sliding));
  EXPECT_NEAR(f(0), -100.0 * 0.02, 1e-12);  // on disc i, away from j (n = +x)
  EXPECT_NEAR(f(3), +100.0 * 0.02, 1e-12);  // on disc j
  EXPECT_NEAR(f.norm(), std::sqrt(2.0) * 2.0, 1e-12);
  EXPECT_NEAR(m(0, 0), 0.01 * 100.0, 1e-12);
  EXPECT_NEAR(m(0, 3), -0.01 * 100.0, 1e-12);
  EXPECT_FALSE(sliding);
  // Beyond the coronas nothing acts, and the block is left as it was.
  const PairGeometry far = PairGeometry::make(Vec2(1.06, 0.0), 0.5, 0.5);
  EXPECT_FALSE(laws.add_blocks(far, none, 0.01, m, f, sliding));
}

}  // namespace
}  // namespace sheardiff
