// The pressure-driven channel (issue 15): the fluid solve against its analytic limits, the flux
// held to round-off, the mirror symmetry of the dynamics, the observer's table columns.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "scratch_dir.hpp"
#include "sheardiff/interactions/fluid_layer.hpp"
#include "sheardiff/interactions/stokes_drag.hpp"
#include "sheardiff/io/hdf5_tables.hpp"
#include "sheardiff/observe/channel.hpp"
#include "sheardiff/run.hpp"
#include "sheardiff/solver/resistance_system.hpp"

namespace sheardiff {
namespace {

ImposedFlow poiseuille(double y_lo, double height, double u) {
  ImposedFlow f;
  f.y0 = y_lo;
  f.span = height;
  f.gammadot = 6.0 * u / height;
  f.curvature = -6.0 * u / (height * height);
  f.rate = 2.0 * u;
  return f;
}

struct FluidSolve {
  std::vector<double> w;  // the deviation at the interior nodes
  double g = 0.0;         // the pressure gradient
  VecX u;
};

// Solves the fluid layer with `p`'s mobile particles pinned (a penalty resistance `pin` on their
// translation; no rotational unknowns) against the reference flow.
FluidSolve solve_pinned(const Particles& p, const FluidLayer& fl, const ImposedFlow& ref,
                        double pin) {
  ResistanceSystem sys(2, "cholmod");
  const int base = 2 * static_cast<int>(p.n_mobile);
  std::vector<double> heights;
  for (std::size_t i = 0; i < p.n_mobile; ++i) heights.push_back(p.position[i].y());
  sys.set_pattern(p.n_mobile, {}, p, false, fl.unknowns(), fl.pattern(heights, 2, base));
  sys.clear();
  for (std::size_t i = 0; i < p.n_mobile; ++i) {
    const Vec3 zeta = StokesDrag::resistance(p.radius[i]);
    sys.add_self(static_cast<int>(i), Vec3(zeta + Vec3(pin, pin, 0.0)),
                 Vec3(zeta.cwiseProduct(ref.velocity(p.position[i]))));
  }
  fl.assemble(p, ref, 2, base, sys);
  FluidSolve s;
  double m = 0.0;
  EXPECT_TRUE(sys.solve_with_multiplier(s.u, fl.load(sys.unknowns(), base), m));
  s.g = m;
  s.w.assign(s.u.data() + base, s.u.data() + s.u.size());
  return s;
}

// No particles: the fluid is Poiseuille with G = 12 eta <u> / H^2. Linear elements with the
// load integrated exactly reproduce a quadratic's nodal values, so the deviation vanishes to
// round-off even on a coarse grid (a wrong sign or factor in the viscous term, the reference
// load or the multiplier would leave w of order <u>).
TEST(ChannelFluid, WithoutParticlesPoiseuilleAndItsExactPressureGradient) {
  const double h = 7.3, u = 1.7;
  for (int cells : {4, 9, 40}) {
    Particles none;
    const FluidLayer fl(0.5, 0.5 + h, cells, 3.0, 1.0, 0.15);
    const ImposedFlow ref = poiseuille(0.5, h, u);
    const FluidSolve s = solve_pinned(none, fl, ref, 0.0);
    for (double w : s.w) EXPECT_NEAR(w, 0.0, 1e-12 * u) << cells << " cells";
    EXPECT_NEAR(s.g, 12.0 * u / (h * h), 1e-12 * s.g) << cells << " cells";
  }
}

// A uniform array of fixed particles: the fluid obeys eta U'' - alpha U + G = 0 (Brinkman) with
// alpha = (drag per particle) x (particles per unit area) / l_z, whose solution at fixed mean
// velocity is U = (G/alpha)(1 - cosh(k s)/cosh(k H/2)), k^2 = alpha/eta, G = alpha <u> /
// (1 - tanh(x)/x), x = k H/2. Particles sit on every node (a row of m per node), so the drag
// density is uniform on the grid; their radius shrinks with the spacing so that alpha (k H/2 = 3:
// a boundary layer of H/6) stays the same on every grid. Linear elements converge at second
// order: the error must fall about 4x per halving of the spacing (asserted: 3x) and be below
// 1e-3 of <u> at 160 cells.
TEST(ChannelFluid, FixedArrayGivesTheBrinkmanProfile) {
  const double height = 10.0, lx = 4.0, lz = 1.0, u = 1.0, pin = 1e13;
  const int per_node = 2;
  const double k = 6.0 / height, alpha = k * k, x = 0.5 * k * height;
  double last_err = 0.0;
  for (int cells : {40, 80, 160}) {
    const double hgrid = height / cells;
    // 3 pi d per particle: alpha = 3 pi (2 a) per_node / (lx hgrid lz).
    const double a = alpha * lx * hgrid * lz / (6.0 * kPi * per_node);
    Particles p;
    p.resize(static_cast<std::size_t>(per_node * (cells - 1)));
    p.n_mobile = p.size();
    for (int n = 1; n < cells; ++n)
      for (int m = 0; m < per_node; ++m) {
        const auto i = static_cast<std::size_t>(per_node * (n - 1) + m);
        p.position[i] = Vec2((m + 0.5) * lx / per_node, n * hgrid);
        p.radius[i] = a;
      }
    const FluidLayer fl(0.0, height, cells, lx, lz, 0.1);
    const ImposedFlow ref = poiseuille(0.0, height, u);
    const FluidSolve s = solve_pinned(p, fl, ref, pin);
    // The pinned particles barely move (the penalty's error, ~ drag / pin).
    EXPECT_LT(s.u.head(2 * static_cast<Eigen::Index>(p.n_mobile)).cwiseAbs().maxCoeff(), 1e-9);
    const double g = alpha * u / (1.0 - std::tanh(x) / x);
    double err = std::abs(s.g - g) / g;
    for (int n = 1; n < cells; ++n) {
      const double y = n * hgrid;
      const double exact = g / alpha * (1.0 - std::cosh(k * (y - 0.5 * height)) / std::cosh(x));
      const double fem = ref.velocity(Vec2(0.0, y)).x() + s.w[static_cast<std::size_t>(n - 1)];
      err = std::max(err, std::abs(fem - exact) / u);
    }
    if (last_err > 0.0) {
      EXPECT_LT(err, last_err / 3.0) << cells << " cells";
    }
    last_err = err;
  }
  EXPECT_LT(last_err, 1e-3);
}

Config channel_config(double phi, double h_over_a, std::int64_t seed) {
  Config c;
  c.scene.type = "channel";
  c.particles.size_ratio = 1.0;
  c.channel.phi = phi;
  c.channel.h_over_a = h_over_a;
  c.channel.wall_discs = 9;
  c.contact.mu = 0.0;
  c.analysis.diffusion = false;
  c.run.seed = seed;
  c.run.strain = 50.0;
  resolve_defaults(c);
  return c;
}

// Every step of a two-way run holds the mean fluid velocity at <u> to round-off (the multiplier
// is exact), and the suspension needs a larger pressure gradient than pure fluid.
TEST(Channel, FluxHeldToRoundOffAndPressureGradientAbovePoiseuille) {
  const Config c = channel_config(0.4, 18.32, 2);
  Simulation sim(c);
  const FluidLayer& fl = *sim.dynamics().force_balance().fluid();
  const double h = c.channel.h_over_a * 0.5, g0 = 12.0 * c.channel.mean_velocity / (h * h);
  double g_sum = 0.0;
  for (int k = 0; k < 400; ++k) {
    sim.step();
    const Velocities& v = sim.integrator().velocities();
    ASSERT_EQ(v.fluid.size(), fl.unknowns());
    double flux = 0.0;  // int w dy of the deviation (the reference carries <u> H exactly)
    for (double w : v.fluid) flux += w * fl.spacing();
    ASSERT_LT(std::abs(flux), 1e-12 * c.channel.mean_velocity * h) << "step " << k;
    g_sum += v.pressure_gradient;
  }
  EXPECT_GT(g_sum / 400.0, 1.2 * g0);
}

// The channel is symmetric under the mirror y -> y_lo + y_hi - y: a mirrored start must stay
// the mirror image of the original, step by step (to round-off, over a short run before chaos
// amplifies it). A sign error in the fluid's rotational coupling or the grid's orientation
// breaks this at the first step.
TEST(Channel, MirroredStartStaysMirrored) {
  const Config c = channel_config(0.35, 14.02, 4);
  Simulation a(c);
  Scene mirrored = build_scene(c);
  const double top = c.channel.h_over_a * 0.5 + 1.0;  // wall centre lines at 0 and H + 2a
  for (std::size_t i = 0; i < mirrored.particles.n_mobile; ++i) {
    Vec2& x = mirrored.particles.position[i];
    x.y() = top - x.y();
    mirrored.particles.unwrapped[i] = x;
  }
  Simulation b(c, std::move(mirrored));
  for (int k = 0; k < 300; ++k) {
    a.step();
    b.step();
    ASSERT_NEAR(a.dynamics().time(), b.dynamics().time(), 1e-9 * a.dynamics().time());
  }
  const Particles& pa = a.dynamics().particles();
  const Particles& pb = b.dynamics().particles();
  double err = 0.0;
  for (std::size_t i = 0; i < pa.n_mobile; ++i) {
    err = std::max(err, std::abs(pa.unwrapped[i].x() - pb.unwrapped[i].x()));
    err = std::max(err, std::abs(pa.unwrapped[i].y() - (top - pb.unwrapped[i].y())));
  }
  EXPECT_LT(err, 1e-6);
}

// The progress line's status: nothing before the first sample interval closes, then the last
// interval's centre distance and pressure-gradient ratio, the same numbers as the history's last
// row in the summary (a mismatch would mean the user watches another quantity than the one stored).
TEST(Channel, ProgressReportsTheLastIntervalOfTheHistory) {
  Config c = channel_config(0.4, 14.02, 3);
  c.channel.sample_interval = 2.0;
  Simulation sim(c);
  ChannelObserver obs(c);
  EXPECT_TRUE(obs.progress().empty());
  const Dynamics& d = sim.dynamics();
  while (d.strain() < 4.5) {
    sim.step();
    const StressSample s = sim.sample();
    obs.on_step(StepView{d, sim.integrator().velocities(), s, sim.integrator().last_dt(),
                         sim.integrator().stages(d)});
  }
  const std::string text = obs.progress();
  const ChannelHistory h = obs.history(d);
  ASSERT_EQ(h.time.size(), 3u);  // two closed intervals and the open one
  const double c1 = h.centre_distance[1], g1 = h.pressure_gradient_ratio[1];
  EXPECT_NE(text.find(fmt::format("centre distance {:.3f} d", c1)), std::string::npos) << text;
  EXPECT_NE(text.find(fmt::format("G/G0 {:.3f}", g1)), std::string::npos) << text;
  EXPECT_NE(text.find("not yet steady"), std::string::npos) << text;
}

// One-way coupling: a fixed Poiseuille background, the pressure gradient is Poiseuille's; the
// run's summary carries the seed's Table 1 columns with their definitions' bounds.
TEST(Channel, SummaryColumnsOneAndTwoWay) {
  for (const char* coupling : {"one_way", "two_way"}) {
    Config c = channel_config(0.3, 14.02, 1);
    c.channel.coupling = coupling;
    c.channel.sample_interval = 5.0;
    c.output.frame_strain = 5.0;
    c.output.trajectory = false;
    c.run.strain = 20.0;
    const ScratchDir dir(coupling);
    const nlohmann::json js = run_to_directory(c, dir, false);
    // The history is in DIR/channel.h5 (rows every 5 a/<u>: the last interval closes at the
    // run's end, or is still open), not in the summary.
    EXPECT_FALSE(js.contains("channel_history"));
    EXPECT_EQ(js["channel_history_file"], "channel.h5");
    const auto time = read_dataset(dir / "channel.h5", "/channel_history/time");
    EXPECT_GE(time.size(), 3u);
    EXPECT_NEAR(time.back(), js["strain"].get<double>(), 1e-9);
    const auto phi_rows = read_dataset(dir / "channel.h5", "/channel_history/phi");
    EXPECT_EQ(phi_rows.size(), time.size() * js["channel_y"].size());
    const bool two_way = std::string(coupling) == "two_way";
    EXPECT_EQ(js["channel_coupling"], coupling);
    if (!two_way) {
      EXPECT_DOUBLE_EQ(js["channel_dp_ratio"].get<double>(), 1.0);
    } else {
      EXPECT_GT(js["channel_dp_ratio"].get<double>(), 1.0);
    }
    // phi integrates to phi_b: the bins tile the channel; a disc resting in a dip of a wall
    // row reaches below its surface by up to (2 - sqrt 3) a, an area left out of the bins:
    // allow 2 %.
    double phi = 0.0;
    for (const auto& x : js["channel_phi"]) phi += x.get<double>();
    phi /= static_cast<double>(js["channel_phi"].size());
    EXPECT_NEAR(phi, 0.3, 0.02 * 0.3);
    // The fluid profile has the mean <u> = 1 (bin midpoint rule on a profile that is
    // quadratic within the seed's a/2 bins: within 1 %).
    double uf = 0.0;
    for (const auto& x : js["channel_u_f"]) uf += x.get<double>();
    EXPECT_NEAR(uf / static_cast<double>(js["channel_u_f"].size()), 1.0, 0.01);
  }
}

// Bad channel input is refused before any work, naming the key.
TEST(Channel, RefusesPolydisperseAndShearAnalyses) {
  const std::string base = "[scene]\ntype = \"channel\"\n[analysis]\ndiffusion = false\n";
  EXPECT_THROW(
      {
        try {
          parse_config(base, "t.toml");
        } catch (const ConfigError& e) {
          EXPECT_NE(std::string(e.what()).find("particles.size_ratio"), std::string::npos);
          throw;
        }
      },
      ConfigError);
  EXPECT_THROW(
      {
        try {
          parse_config("[scene]\ntype = \"channel\"\n[particles]\nsize_ratio = 1.0\n", "t.toml");
        } catch (const ConfigError& e) {
          EXPECT_NE(std::string(e.what()).find("analysis.diffusion"), std::string::npos);
          throw;
        }
      },
      ConfigError);
  EXPECT_NO_THROW(
      parse_config(base + "[particles]\nsize_ratio = 1.0\n[run]\nstrain = 100\n", "t.toml"));
}

// channel.h5 round trip: float64 series exact, the profiles to float32 precision, an empty bin
// (NaN) stays NaN; a ragged table is refused rather than written shifted.
TEST(Channel, HistoryFileRoundTrip) {
  ChannelHistory h;
  h.y = {0.25, 0.75};
  h.time = {5.0, 10.0};
  h.pressure_gradient_ratio = {2.0, 2.1};
  h.centre_distance = {4.0, 4.25};
  h.u_p_mean = {0.97, 0.98};
  for (auto& rows : h.profiles) rows = {{0.123456789, NAN}, {1.0 / 3.0, 2.0}};
  const ScratchDir dir;
  const auto file = dir / "channel_history.h5";
  write_channel_history(h, file);
  EXPECT_EQ(read_dataset(file, "/channel_history/centre_distance"), h.centre_distance);
  for (const char* name : ChannelHistory::profile_names) {
    const auto v = read_dataset(file, std::string("/channel_history/") + name);
    ASSERT_EQ(v.size(), 4u) << name;
    EXPECT_NEAR(v[0], 0.123456789, 1e-7) << name;
    EXPECT_TRUE(std::isnan(v[1])) << name;
    EXPECT_NEAR(v[2], 1.0 / 3.0, 1e-7) << name;
  }
  EXPECT_THROW(read_dataset(file, "/channel_history/missing"), std::runtime_error);
  std::filesystem::remove(file);
  h.profiles[2][1].pop_back();
  EXPECT_THROW(write_channel_history(h, file), std::logic_error);
}

}  // namespace
}  // namespace sheardiff
