// The run configuration (src/config.cpp): defaults, round trip through TOML, and errors that
// name the origin, the key and the allowed range.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "scratch_dir.hpp"
#include "sheardiff/config.hpp"
#include "sheardiff/run.hpp"
#include "sheardiff/run_extension.hpp"

namespace sheardiff {
namespace {

// Every field of two configurations, compared exactly (a round trip must not lose a bit), after
// the defaults that depend on other keys are filled in (output.frame_strain from J).
void expect_same_config(Config a, Config b) {
  resolve_defaults(a);
  resolve_defaults(b);
  EXPECT_EQ(a.scene.type, b.scene.type);
  EXPECT_EQ(a.particles.n, b.particles.n);
  EXPECT_EQ(a.particles.mix, b.particles.mix);
  EXPECT_EQ(a.particles.size_ratio, b.particles.size_ratio);
  EXPECT_EQ(a.particles.phi_init, b.particles.phi_init);
  EXPECT_EQ(a.particles.aspect, b.particles.aspect);
  EXPECT_EQ(a.particles.init_file, b.particles.init_file);
  EXPECT_EQ(a.particles.init_frame, b.particles.init_frame);
  EXPECT_EQ(a.flow.j, b.flow.j);
  EXPECT_EQ(a.flow.lz, b.flow.lz);
  EXPECT_EQ(a.lubrication.enabled, b.lubrication.enabled);
  EXPECT_EQ(a.lubrication.delta, b.lubrication.delta);
  EXPECT_EQ(a.lubrication.h_max, b.lubrication.h_max);
  EXPECT_EQ(a.contact.ktilde, b.contact.ktilde);
  EXPECT_EQ(a.contact.kt_ratio, b.contact.kt_ratio);
  EXPECT_EQ(a.contact.mu, b.contact.mu);
  EXPECT_EQ(a.integrator.type, b.integrator.type);
  EXPECT_EQ(a.integrator.dt, b.integrator.dt);
  EXPECT_EQ(a.integrator.max_displacement, b.integrator.max_displacement);
  EXPECT_EQ(a.integrator.max_gap_fraction, b.integrator.max_gap_fraction);
  EXPECT_EQ(a.integrator.max_overlap_change, b.integrator.max_overlap_change);
  EXPECT_EQ(a.integrator.max_entry_overlap, b.integrator.max_entry_overlap);
  EXPECT_EQ(a.integrator.max_strain_step, b.integrator.max_strain_step);
  EXPECT_EQ(a.integrator.explicit_safety, b.integrator.explicit_safety);
  EXPECT_EQ(a.neighbour.skin, b.neighbour.skin);
  EXPECT_EQ(a.run.strain, b.run.strain);
  EXPECT_EQ(a.run.seed, b.run.seed);
  EXPECT_EQ(a.run.max_steps, b.run.max_steps);
  EXPECT_EQ(a.run.transient_strain, b.run.transient_strain);
  EXPECT_EQ(a.walls.free_fall_speed, b.walls.free_fall_speed);
  EXPECT_EQ(a.walls.jitter, b.walls.jitter);
  EXPECT_EQ(a.steady.window, b.steady.window);
  EXPECT_EQ(a.steady.h_tolerance, b.steady.h_tolerance);
  EXPECT_EQ(a.steady.mu_tolerance, b.steady.mu_tolerance);
  EXPECT_EQ(a.steady.measure_strain, b.steady.measure_strain);
  EXPECT_EQ(a.observables.wall_exclusion, b.observables.wall_exclusion);
  EXPECT_EQ(a.observables.profile_bin, b.observables.profile_bin);
  EXPECT_EQ(a.output.frame_strain, b.output.frame_strain);
  EXPECT_EQ(a.output.velocities, b.output.velocities);
  EXPECT_EQ(a.output.trajectory, b.output.trajectory);
  EXPECT_EQ(a.output.checkpoint_strain, b.output.checkpoint_strain);
  EXPECT_EQ(a.solver.cholesky, b.solver.cholesky);
  EXPECT_EQ(a.analysis.diffusion, b.analysis.diffusion);
  EXPECT_EQ(a.analysis.msd_window_lo, b.analysis.msd_window_lo);
  EXPECT_EQ(a.analysis.msd_window_hi, b.analysis.msd_window_hi);
  EXPECT_EQ(a.analysis.reference_times, b.analysis.reference_times);
  EXPECT_EQ(a.analysis.vacf_max_lag, b.analysis.vacf_max_lag);
  EXPECT_EQ(a.analysis.sample_strain, b.analysis.sample_strain);
  EXPECT_EQ(a.analysis.coarse_strain, b.analysis.coarse_strain);
}

// The message of the ConfigError thrown by parse_config, or "" (and a failure) if none is.
std::string config_error(const std::string& toml, const std::vector<std::string>& overrides = {},
                         const std::string& origin = "test.toml") {
  try {
    parse_config(toml, origin, overrides);
  } catch (const ConfigError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected ConfigError, got another exception: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected ConfigError for:\n" << toml;
  return "";
}

#define EXPECT_CONTAINS(text, piece) \
  EXPECT_NE(std::string(text).find(piece), std::string::npos) << "message: " << (text)

TEST(Config, EmptyDocumentGivesTheDefaults) {
  const Config def;
  const Config cfg = parse_config("", "empty.toml");
  expect_same_config(cfg, def);
  // The documented defaults (docs/model.md section 10 and docs/config.md).
  EXPECT_EQ(cfg.scene.type, "simple_shear");
  EXPECT_EQ(cfg.particles.n, 500);
  EXPECT_EQ(cfg.particles.mix, MixRule::Volume);
  EXPECT_EQ(cfg.particles.size_ratio, 1.4);
  EXPECT_EQ(cfg.flow.j, 1e-2);
  EXPECT_EQ(cfg.flow.lz, 1.0);
  EXPECT_TRUE(cfg.lubrication.enabled);
  EXPECT_EQ(cfg.lubrication.delta, 0.01);
  EXPECT_EQ(cfg.lubrication.h_max, 0.5);
  EXPECT_EQ(cfg.contact.ktilde, 1e4);
  EXPECT_EQ(cfg.contact.kt_ratio, 0.5);
  EXPECT_EQ(cfg.contact.mu, 0.5);
  EXPECT_EQ(cfg.integrator.type, IntegratorType::Implicit);
  EXPECT_EQ(cfg.integrator.max_displacement, 1e-3);
}

TEST(Config, MinimalDocumentSetsValuesAndKeepsDefaults) {
  const std::string toml = R"(
[particles]
N = 120
mix = "volume"

[flow]
J = 3e-4

[contact]
ktilde = 100      # an integer is accepted for a real key
mu = 0.0

[integrator]
type = "heun"

[lubrication]
enabled = false
)";
  const Config cfg = parse_config(toml, "min.toml");
  EXPECT_EQ(cfg.particles.n, 120);
  EXPECT_EQ(cfg.particles.mix, MixRule::Volume);
  EXPECT_EQ(cfg.flow.j, 3e-4);
  EXPECT_EQ(cfg.contact.ktilde, 100.0);
  EXPECT_EQ(cfg.contact.mu, 0.0);
  EXPECT_EQ(cfg.integrator.type, IntegratorType::Heun);
  EXPECT_FALSE(cfg.lubrication.enabled);
  // Everything not set keeps its default.
  Config want;
  want.particles.n = 120;
  want.particles.mix = MixRule::Volume;
  want.flow.j = 3e-4;
  want.contact.ktilde = 100.0;
  want.contact.mu = 0.0;
  want.integrator.type = IntegratorType::Heun;
  want.lubrication.enabled = false;
  expect_same_config(cfg, want);
}

TEST(Config, ToTomlRoundTrips) {
  // Defaults, and a configuration with values that need all 17 significant digits.
  expect_same_config(parse_config(to_toml(Config{}), "resolved.toml"), Config{});

  Config c;
  c.scene.type = "pressure_shear";
  c.particles.n = 777;
  c.particles.mix = MixRule::Number;
  c.particles.size_ratio = 1.3;
  c.particles.phi_init = 0.1 + 0.2;  // 0.30000000000000004
  c.particles.aspect = 2.5;
  c.particles.init_file = "runs/start frame.h5";
  c.particles.init_frame = 12;
  c.flow.j = 1.0 / 3.0 * 1e-3;
  c.flow.lz = 0.5;
  c.lubrication.enabled = false;
  c.lubrication.delta = 0.02;
  c.lubrication.h_max = 0.4;
  c.contact.ktilde = 123456.789;
  c.contact.kt_ratio = 2.0 / 7.0;
  c.contact.mu = 1.0;
  c.integrator.type = IntegratorType::Euler;
  c.integrator.dt = 1e-3;
  c.integrator.max_displacement = 2e-3;
  c.integrator.max_gap_fraction = 0.25;
  c.integrator.max_overlap_change = 5e-4;
  c.integrator.max_entry_overlap = 7e-4;
  c.integrator.max_strain_step = 3e-3;
  c.integrator.explicit_safety = 0.7;
  c.neighbour.skin = 0.45;
  c.run.strain = 20.0;
  c.run.seed = 4242424242424242;
  c.run.max_steps = 1000000;
  c.run.transient_strain = 5.0;
  c.walls.free_fall_speed = 0.1;
  c.walls.jitter = 0.0;
  c.steady.window = 3.0;
  c.steady.h_tolerance = 0.02;
  c.steady.mu_tolerance = 0.1;
  c.steady.measure_strain = 4.0;
  c.observables.wall_exclusion = 2.0;
  c.observables.profile_bin = 0.25;
  c.output.frame_strain = 0.02;
  c.analysis.sample_strain = 0.003;
  c.analysis.coarse_strain = 0.07;
  c.output.velocities = false;
  c.output.trajectory = false;
  const std::string text = to_toml(c);
  const Config back = parse_config(text, "resolved.toml");
  SCOPED_TRACE(text);
  expect_same_config(back, c);
  // Idempotent: printing the parsed copy gives the same text.
  EXPECT_EQ(to_toml(back), text);
}

TEST(Config, UnknownKeySuggestsTheNearMiss) {
  const std::string msg = config_error("[flow]\nj = 1e-3\n", {}, "runs/a.toml");
  EXPECT_CONTAINS(msg, "runs/a.toml");
  EXPECT_CONTAINS(msg, "flow.j");
  EXPECT_CONTAINS(msg, "unknown key");
  EXPECT_CONTAINS(msg, "did you mean 'flow.J'");
  // A key far from every known one gets no suggestion.
  const std::string far = config_error("[flow]\nzzzzzzzzzz = 1\n");
  EXPECT_CONTAINS(far, "flow.zzzzzzzzzz");
  EXPECT_CONTAINS(far, "unknown key");
  EXPECT_EQ(far.find("did you mean"), std::string::npos) << far;
  // Unknown section, and a top-level key outside any section.
  EXPECT_CONTAINS(config_error("[contacts]\nmu = 0.3\n"), "contacts.mu");
  EXPECT_CONTAINS(config_error("seed = 3\n"), "seed");
}

TEST(Config, OutOfRangeValuesNameKeyAndRange) {
  // flow.J lives in (0, 10]: 0 itself is excluded.
  const std::string j0 = config_error("[flow]\nJ = 0\n");
  EXPECT_CONTAINS(j0, "test.toml");
  EXPECT_CONTAINS(j0, "flow.J");
  EXPECT_CONTAINS(j0, "[1e-10, 10]");
  EXPECT_CONTAINS(config_error("[flow]\nJ = 10.5\n"), "[1e-10, 10]");
  // The boundaries themselves are accepted where closed.
  EXPECT_EQ(parse_config("[flow]\nJ = 10\n", "t").flow.j, 10.0);
  // particles.N is an integer in [2, 1e6].
  const std::string nn = config_error("[particles]\nN = -5\n");
  EXPECT_CONTAINS(nn, "particles.N");
  EXPECT_CONTAINS(nn, "-5");
  EXPECT_CONTAINS(nn, "[2, 1e+06]");
  EXPECT_CONTAINS(config_error("[particles]\nN = 1\n"), "particles.N");
  // lubrication.h_max must stay below 1 (docs/model.md section 10) and above 0.
  EXPECT_CONTAINS(config_error("[lubrication]\nh_max = 1.5\n"), "lubrication.h_max");
  EXPECT_CONTAINS(config_error("[lubrication]\ndelta = 0.0\n"), "lubrication.delta");
  // Non-finite reals are rejected.
  EXPECT_CONTAINS(config_error("[contact]\nktilde = inf\n"), "contact.ktilde");
  EXPECT_CONTAINS(config_error("[contact]\nktilde = nan\n"), "contact.ktilde");
}

TEST(Config, WrongTypeNamesKeyAndExpectedType) {
  const std::string msg = config_error("[contact]\nktilde = \"stiff\"\n");
  EXPECT_CONTAINS(msg, "contact.ktilde");
  EXPECT_CONTAINS(msg, "\"stiff\"");
  EXPECT_CONTAINS(msg, "a number in [1, 1e+09]");
  // A real where an integer is required, and a number where a bool is.
  const std::string nreal = config_error("[particles]\nN = 100.5\n");
  EXPECT_CONTAINS(nreal, "particles.N");
  EXPECT_CONTAINS(nreal, "an integer");
  EXPECT_CONTAINS(config_error("[output]\nvelocities = 1\n"), "true or false");
  // A section that is not a table.
  EXPECT_CONTAINS(config_error("flow = 3\n"), "flow");
}

TEST(Config, BadEnumValueListsTheChoices) {
  const std::string msg = config_error("[integrator]\ntype = \"rk4\"\n");
  EXPECT_CONTAINS(msg, "integrator.type");
  EXPECT_CONTAINS(msg, "\"rk4\"");
  EXPECT_CONTAINS(msg, "one of \"implicit\" \"euler\" \"heun\"");
  EXPECT_CONTAINS(config_error("[particles]\nmix = \"mass\"\n"), "\"area\" \"volume\" \"number\"");
  EXPECT_CONTAINS(config_error("[scene]\ntype = \"couette\"\n"), "scene.type");
}

TEST(Config, NotTomlNamesOriginAndLine) {
  // The error is on line 3 (an unterminated table header).
  const std::string msg = config_error("[flow]\nJ = 1e-3\n[contact\nmu = 0.2\n", {}, "bad.toml");
  EXPECT_CONTAINS(msg, "bad.toml:3:");
  EXPECT_CONTAINS(msg, "not valid TOML");
  // A duplicated key is also a TOML error, reported on the line of the duplicate (3).
  EXPECT_CONTAINS(config_error("[flow]\nJ = 1\nJ = 2\n", {}, "dup.toml"), "dup.toml:3:");
}

TEST(Config, SetOverridesAreAppliedAndValidated) {
  const std::string base = "[flow]\nJ = 1e-2\n";
  const Config cfg = parse_config(base, "base.toml",
                                  {"flow.J=1e-3", "integrator.type=heun", "particles.N=64",
                                   "lubrication.enabled=false", "scene.type=\"pressure_shear\""});
  EXPECT_EQ(cfg.flow.j, 1e-3);
  EXPECT_EQ(cfg.integrator.type, IntegratorType::Heun);  // bare word taken as a string
  EXPECT_EQ(cfg.particles.n, 64);
  EXPECT_FALSE(cfg.lubrication.enabled);
  EXPECT_EQ(cfg.scene.type, "pressure_shear");
  // Later overrides win.
  EXPECT_EQ(parse_config(base, "b", {"flow.J=0.5", "flow.J=0.25"}).flow.j, 0.25);

  const std::string abc = config_error(base, {"flow.J=abc"});
  EXPECT_CONTAINS(abc, "--set");
  EXPECT_CONTAINS(abc, "flow.J");
  EXPECT_CONTAINS(abc, "abc");
  EXPECT_CONTAINS(abc, "[1e-10, 10]");
  const std::string range = config_error(base, {"flow.J=0"});
  EXPECT_CONTAINS(range, "flow.J");
  EXPECT_CONTAINS(range, "[1e-10, 10]");
  const std::string unknown = config_error(base, {"flow.j=1e-3"});
  EXPECT_CONTAINS(unknown, "--set");
  EXPECT_CONTAINS(unknown, "unknown key");
  EXPECT_CONTAINS(unknown, "did you mean 'flow.J'");
  const std::string shape = config_error(base, {"flowJ"});
  EXPECT_CONTAINS(shape, "section.key=value");
}

TEST(Config, TransientMustEndBeforeTheRun) {
  const std::string msg = config_error("[run]\nstrain = 2.0\ntransient_strain = 3.0\n");
  EXPECT_CONTAINS(msg, "run.transient_strain");
  EXPECT_CONTAINS(msg, "run.strain");
  // Equal is rejected too (nothing would be averaged).
  EXPECT_CONTAINS(config_error("[run]\nstrain = 2.0\ntransient_strain = 2.0\n"),
                  "run.transient_strain");
  // The check also sees values from --set.
  EXPECT_CONTAINS(config_error("[run]\nstrain = 2.0\n", {"run.transient_strain=2.5"}),
                  "run.transient_strain");
  // Smaller is fine.
  EXPECT_EQ(parse_config("[run]\nstrain = 2.0\ntransient_strain = 1.5\n", "t").run.transient_strain,
            1.5);
}

TEST(Config, OtherCombinationChecks) {
  EXPECT_CONTAINS(config_error("[particles]\nphi_init = 0.88\n"), "particles.phi_init");
  EXPECT_CONTAINS(config_error("[run]\nstrain = 0.5\n[output]\nframe_strain = 0.6\n"),
                  "output.frame_strain");
}

TEST(Config, ReferenceTableListsEveryKey) {
  const std::string md = config_reference_markdown();
  for (const char* key : {"`scene.type`", "`particles.N`", "`flow.J`", "`contact.ktilde`",
                          "`integrator.type`", "`run.transient_strain`", "`output.trajectory`"})
    EXPECT_CONTAINS(md, key);
  EXPECT_STREQ(to_string(IntegratorType::Implicit), "implicit");
  EXPECT_STREQ(to_string(MixRule::Volume), "volume");
}

}  // namespace
}  // namespace sheardiff

namespace sheardiff {
namespace {

TEST(Config, OverlapChangeLimitFollowsTheStiffness) {
  // 0 (the default) = min(max_displacement, 10 d / ktilde): ten typical overlaps per step.
  Config c;
  EXPECT_EQ(c.integrator.max_overlap_change, 0.0);
  EXPECT_DOUBLE_EQ(overlap_change_limit(c), 1e-3);  // ktilde 1e4: the displacement limit
  c.contact.ktilde = 1e5;
  EXPECT_DOUBLE_EQ(overlap_change_limit(c), 1e-4);
  c.contact.ktilde = 1e3;
  EXPECT_DOUBLE_EQ(overlap_change_limit(c), 1e-3);
  c.integrator.max_displacement = 3e-3;
  EXPECT_DOUBLE_EQ(overlap_change_limit(c), 3e-3);
  c.integrator.max_overlap_change = 5e-4;  // given explicitly: taken as is
  EXPECT_DOUBLE_EQ(overlap_change_limit(c), 5e-4);
  EXPECT_CONTAINS(config_error("[integrator]\nmax_overlap_change = -1e-4\n"),
                  "integrator.max_overlap_change");
}

}  // namespace
}  // namespace sheardiff

namespace sheardiff {
namespace {

// Issue 16: a directory read as an empty config and ran the default scene; `check` of an empty
// file printed the defaults.
TEST(Config, ConfigFileMustBeAFileNamingItsScene) {
  namespace fs = std::filesystem;
  const ScratchDir dir;
  fs::create_directories(dir / "dir.toml");
  const auto error_of = [](const fs::path& f, std::vector<std::string> sets = {}) {
    try {
      load_config(f, sets);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_CONTAINS(error_of(dir / "dir.toml"), "it is a directory, not a TOML file");
  EXPECT_CONTAINS(error_of(dir / "missing.toml"), "cannot open the config file: No such file");
  std::ofstream(dir / "empty.toml") << "";
  EXPECT_CONTAINS(error_of(dir / "empty.toml"), "empty.toml: scene.type: missing");
  std::ofstream(dir / "flow.toml") << "# a comment\n[flow]\nJ = 1e-3\n";
  EXPECT_CONTAINS(error_of(dir / "flow.toml"), "scene.type: missing");
  EXPECT_EQ(error_of(dir / "flow.toml", {"scene.type=simple_shear"}), "");
  std::ofstream(dir / "scene.toml") << "[scene]\ntype = \"pressure_shear\"\n";
  EXPECT_EQ(load_config(dir / "scene.toml").scene.type, "pressure_shear");
}

// Issue 16: frame_strain (or checkpoint_strain) = 1e-300 was in range and spun forever.
TEST(Config, OutputSpacingsAreBoundedByTheRunStrain) {
  const std::string frames = config_error("[output]\nframe_strain = 1e-300\n");
  EXPECT_CONTAINS(frames, "output.frame_strain: 1e-300 asks for run.strain / output.frame_strain");
  EXPECT_CONTAINS(frames, "at most 1e+07 are allowed, i.e. output.frame_strain >= 1e-07");
  EXPECT_CONTAINS(config_error("[output]\ncheckpoint_strain = 1e-300\n"),
                  "output.checkpoint_strain >= 1e-07");
  EXPECT_CONTAINS(config_error("[run]\nstrain = 2.0\n[output]\nframe_strain = 1e-7\n"),
                  "output.frame_strain >= 2e-07");
  EXPECT_EQ(parse_config("[output]\nframe_strain = 1e-7\ncheckpoint_strain = 1e-7\n", "t")
                .output.frame_strain,
            1e-7);
  EXPECT_EQ(parse_config("[output]\ncheckpoint_strain = 0\n", "t").output.checkpoint_strain, 0.0);
}

// Issue 16: J = 1e-300 and delta = 1e-300 failed in the solve with advice about
// max_displacement.
TEST(Config, TinyJAndDeltaAreOutOfRange) {
  EXPECT_CONTAINS(config_error("[flow]\nJ = 1e-300\n"), "expected a number in [1e-10, 10]");
  EXPECT_CONTAINS(config_error("[lubrication]\ndelta = 1e-300\n"),
                  "expected a number in [1e-10, 0.5]");
  EXPECT_EQ(parse_config("[flow]\nJ = 1e-10\n", "t").flow.j, 1e-10);
}

// Issue 16: TOML read the text after a line break in a --set value as further keys.
TEST(Config, SetValueWithALineBreakIsRefused) {
  const std::string e = config_error("", {"flow.J=1e-2\nrun.strain=5"});
  EXPECT_CONTAINS(e, "--set flow.J=1e-2: the value holds a line break");
}

// The frame catch-up advances as repeated addition does, and ends whatever the spacing.
TEST(Config, NextOutputStrainEndsForAnySpacing) {
  double next = 0.02;
  for (const double strain : {0.0199999999999, 0.05, 0.0601, 0.3}) {
    double expected = next;
    while (expected <= strain * (1.0 + 1e-12)) expected += 0.02;
    next = next_output_strain(next, 0.02, strain);
    EXPECT_EQ(next, expected) << strain;
  }
  EXPECT_GT(next_output_strain(1e-300, 1e-300, 1.0), 1.0);
  EXPECT_GT(next_output_strain(0.5, 1e-20, 1.0), 1.0);
  EXPECT_LT(next_output_strain(0.5, 1e-20, 1.0), 1.0 + 1e-11);
}

}  // namespace
}  // namespace sheardiff

namespace sheardiff {
namespace {

// Each default a config file and a record resolve differently (file_defaults): a record that
// does not name the key reads as Config's own value, the one a run from before the default ran
// with; a file of those scenes takes the new one; and a refusal over exactly that change says
// how to keep the record's value. A table entry whose record value is not Config's default
// would make every old run's record read as another run.
TEST(Config, AFileDefaultDiffersFromTheRecordsAndTheRefusalSaysHowToKeepIt) {
  const std::string spheres = "[scene]\ntype = \"pressure_shear\"\ndimension = 3\n";
  const Config as_file = parse_config(spheres, "t.toml");
  const Config as_record = parse_config(spheres, "t.toml", {}, ConfigSource::record);
  ASSERT_FALSE(file_defaults().empty());
  for (const auto& d : file_defaults()) {
    ASSERT_TRUE(d.applies(as_file)) << d.key << ": give this test a config of " << d.scenes;
    bool found = false;
    const auto changes = config_changes(to_toml(as_record), to_toml(as_file));
    for (const auto& c : changes)
      if (c.key == d.key) {
        found = true;
        EXPECT_EQ(c.was, d.record_value);
        EXPECT_EQ(c.now, d.file_value);
      }
    EXPECT_TRUE(found) << d.key << " reads the same in a file and a record";
    const std::string hint = changed_default_hint(changes);
    EXPECT_NE(hint.find(d.key), std::string::npos) << hint;
    EXPECT_NE(hint.find(d.scenes), std::string::npos) << hint;
    EXPECT_NE(hint.find("--set " + d.key + "="), std::string::npos) << hint;
    // The other way round (a run of the new default continued with the old) is not this case.
    EXPECT_EQ(changed_default_hint({{d.key, d.file_value, d.record_value}}), "");
  }
  EXPECT_NE(changed_default_hint(config_changes(to_toml(as_record), to_toml(as_file)))
                .find("--set contact.sliding_stiffness=none)"),
            std::string::npos);
}

}  // namespace
}  // namespace sheardiff
