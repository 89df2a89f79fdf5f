// Sweep files, points and fits (the processes and Slurm are tested by tests/sweep/*.sh).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>

#include "scratch_dir.hpp"
#include "sheardiff/config.hpp"
#include "sheardiff/sweep/sweep.hpp"

namespace fs = std::filesystem;
using namespace sheardiff;

namespace {

// base.toml and sweep.toml in DIR; returns sweep.toml.
fs::path write_files(const fs::path& dir, const std::string& sweep) {
  std::ofstream(dir / "base.toml") << "[scene]\ntype = \"pressure_shear\"\n[particles]\nN = 40\n";
  std::ofstream(dir / "sweep.toml") << sweep;
  return dir / "sweep.toml";
}

std::string error_of(const fs::path& file) {
  try {
    load_sweep(file);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Sweep, PointsAreTheProductLastAxisFastest) {
  const ScratchDir scratch;
  const auto file = write_files(scratch, R"(
[sweep]
base = "base.toml"
[sweep.set]
"run.strain" = 2.0
[sweep.axes]
"flow.J" = [0.1, 1e-3]
"contact.ktilde" = [1000, 1e4]
"run.seed" = [1, 2, 3]
)");
  const auto spec = load_sweep(file);
  const auto points = expand_points(spec);
  ASSERT_EQ(points.size(), 12u);
  EXPECT_EQ(points[0].name, "J=0.1_ktilde=1000_seed=1");
  EXPECT_EQ(points[1].name, "J=0.1_ktilde=1000_seed=2");
  EXPECT_EQ(points[3].name, "J=0.1_ktilde=10000_seed=1");
  EXPECT_EQ(points[11].name, "J=0.001_ktilde=10000_seed=3");
  for (size_t i = 0; i < points.size(); ++i) EXPECT_EQ(points[i].index, static_cast<long>(i));
  // The fixed overrides come first, then one per axis, as --set would take them.
  EXPECT_EQ(points[11].overrides, (std::vector<std::string>{"run.strain=2", "flow.J=0.001",
                                                            "contact.ktilde=10000", "run.seed=3"}));
  // Each point's config is the base plus its overrides.
  const Config cfg = load_config(spec.base, points[11].overrides);
  EXPECT_DOUBLE_EQ(cfg.flow.j, 1e-3);
  EXPECT_DOUBLE_EQ(cfg.contact.ktilde, 1e4);
  EXPECT_EQ(cfg.particles.n, 40);
  // Low J costs more steps per strain: it is started first.
  EXPECT_GT(points[11].cost, points[0].cost);
}

// A list key (analysis.velocity_intervals) set for every point reaches each point's config.
TEST(Sweep, ListValuesAreSetAsLists) {
  const ScratchDir scratch;
  const auto file = write_files(scratch, R"(
[sweep]
base = "base.toml"
[sweep.set]
"analysis.velocity_intervals" = [0.0035, 0.01]
[sweep.axes]
"flow.J" = [0.1]
)");
  const auto spec = load_sweep(file);
  const auto points = expand_points(spec);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_EQ(points[0].overrides[0], "analysis.velocity_intervals=[0.0035, 0.01]");
  const Config cfg = load_config(spec.base, points[0].overrides);
  EXPECT_EQ(cfg.analysis.velocity_intervals, (std::vector<double>{0.0035, 0.01}));
  EXPECT_NE(error_of(write_files(ScratchDir("list_bad"),
                                 "[sweep]\nbase = \"base.toml\"\n[sweep.set]\n"
                                 "\"analysis.velocity_intervals\" = [\"a\"]\n"
                                 "[sweep.axes]\n\"flow.J\" = [0.1]\n"))
                .find("a list may only hold numbers"),
            std::string::npos);
}

TEST(Sweep, BadSweepFilesNameTheKey) {
  EXPECT_NE(error_of(write_files(ScratchDir("unknown"),
                                 "[sweep]\nbase = \"base.toml\"\nbsae = 1\n"
                                 "[sweep.axes]\n\"flow.J\" = [0.1]\n"))
                .find("unknown key 'bsae'"),
            std::string::npos);
  EXPECT_NE(error_of(write_files(ScratchDir("nobase"),
                                 "[sweep]\nbase = \"nothere.toml\"\n"
                                 "[sweep.axes]\n\"flow.J\" = [0.1]\n"))
                .find("sweep.base = \"nothere.toml\": no such file"),
            std::string::npos);
  EXPECT_NE(error_of(write_files(ScratchDir("noaxes"), "[sweep]\nbase = \"base.toml\"\n"))
                .find("sweep.axes"),
            std::string::npos);
  EXPECT_NE(error_of(write_files(ScratchDir("emptyaxis"),
                                 "[sweep]\nbase = \"base.toml\"\n"
                                 "[sweep.axes]\n\"flow.J\" = []\n"))
                .find("non-empty list"),
            std::string::npos);
  EXPECT_NE(error_of(write_files(ScratchDir("jobs"),
                                 "[sweep]\nbase = \"base.toml\"\njobs = 0\n"
                                 "[sweep.axes]\n\"flow.J\" = [0.1]\n"))
                .find("sweep.jobs = 0: must be in [1, 256]"),
            std::string::npos);
  // An axis value the config rejects is found before anything runs, with the point's name.
  const auto e = error_of(write_files(ScratchDir("badpoint"),
                                      "[sweep]\nbase = \"base.toml\"\n"
                                      "[sweep.axes]\n\"flow.J\" = [0.1, -1.0]\n"));
  EXPECT_NE(e.find("point J=-1"), std::string::npos) << e;
  EXPECT_NE(e.find("flow.J"), std::string::npos) << e;
  EXPECT_NE(error_of(write_files(ScratchDir("slurm"),
                                 "[sweep]\nbase = \"base.toml\"\n[sweep.axes]\n"
                                 "\"flow.J\" = [0.1]\n[slurm]\nthrotle = 2\n"))
                .find("unknown key 'throtle'"),
            std::string::npos);
}

// A key paired with an axis takes one value per entry of that axis (each J its own start), keeps
// the point names, and a key given in two places is refused rather than one silently winning.
TEST(Sweep, PairedValuesFollowTheirAxis) {
  const ScratchDir scratch;
  const auto file = write_files(scratch, R"(
[sweep]
base = "base.toml"
[sweep.axes]
"flow.J" = [1e-2, 0.1]
"run.seed" = [1, 2]
[sweep.paired."flow.J"]
"particles.phi_init" = [0.74, 0.62]
)");
  const auto spec = load_sweep(file);
  const auto points = expand_points(spec);
  ASSERT_EQ(points.size(), 4u);
  EXPECT_EQ(points[1].name, "J=0.01_seed=2");
  EXPECT_EQ(points[2].name, "J=0.1_seed=1");
  EXPECT_DOUBLE_EQ(load_config(spec.base, points[1].overrides).particles.phi_init, 0.74);
  EXPECT_DOUBLE_EQ(load_config(spec.base, points[2].overrides).particles.phi_init, 0.62);
  EXPECT_DOUBLE_EQ(load_config(spec.base, points[3].overrides).flow.j, 0.1);

  const std::string head =
      "[sweep]\nbase = \"base.toml\"\n[sweep.axes]\n\"flow.J\" = [1e-2, 0.1]\n";
  auto e =
      error_of(write_files(ScratchDir("paired_len"),
                           head + "[sweep.paired.\"flow.J\"]\n\"particles.phi_init\" = [0.7]\n"));
  EXPECT_NE(e.find("sweep.paired.\"flow.J\".\"particles.phi_init\": must be a list of 2 values"),
            std::string::npos)
      << e;
  e = error_of(write_files(ScratchDir("paired_axis"),
                           head + "[sweep.paired.\"run.seed\"]\n\"particles.phi_init\" = [0.7]\n"));
  EXPECT_NE(e.find("\"run.seed\" is not an axis"), std::string::npos) << e;
  e = error_of(
      write_files(ScratchDir("paired_set"), head + "[sweep.set]\n\"particles.phi_init\" = 0.7\n"
                                                   "[sweep.paired.\"flow.J\"]\n"
                                                   "\"particles.phi_init\" = [0.7, 0.6]\n"));
  EXPECT_NE(e.find("also in [sweep.set]"), std::string::npos) << e;
  e = error_of(write_files(ScratchDir("set_and_axis"), head + "[sweep.set]\n\"flow.J\" = 0.3\n"));
  EXPECT_NE(e.find("sweep.set.\"flow.J\": also an axis"), std::string::npos) << e;
  // A bad paired value is found before anything runs, with the point's name.
  e = error_of(
      write_files(ScratchDir("paired_bad"),
                  head + "[sweep.paired.\"flow.J\"]\n\"particles.phi_init\" = [0.7, 2.0]\n"));
  EXPECT_NE(e.find("point J=0.1"), std::string::npos) << e;
  EXPECT_NE(e.find("particles.phi_init"), std::string::npos) << e;
}

// Issue 16: equal axis values raced in one directory and counted twice in the fits; a
// directory as the base config ran the default scene.
TEST(Sweep, DuplicatePointsAndDirectoryBaseAreRefused) {
  EXPECT_NE(
      error_of(write_files(ScratchDir("dupj"),
                           "[sweep]\nbase = \"base.toml\"\n"
                           "[sweep.axes]\n\"flow.J\" = [0.1, 0.01, 1e-1]\n"))
          .find("sweep.axes.\"flow.J\": entries 1 and 3 of the list are the same value (0.1)"),
      std::string::npos);
  EXPECT_NE(error_of(write_files(ScratchDir("dupseed"),
                                 "[sweep]\nbase = \"base.toml\"\n"
                                 "[sweep.axes]\n\"flow.J\" = [0.1]\n\"run.seed\" = [1, 1]\n"))
                .find("sweep.axes.\"run.seed\": entries 1 and 2"),
            std::string::npos);
  // Different values, one directory name.
  EXPECT_NE(error_of(write_files(ScratchDir("dupname"),
                                 "[sweep]\nbase = \"base.toml\"\n"
                                 "[sweep.axes]\n\"particles.init_file\" = [\"a_b\", \"a-b\"]\n"))
                .find("one directory name"),
            std::string::npos);
  // Different values, one configuration once the defaults are resolved.
  const std::string frame = fmt::format("{}", 0.035 * std::pow(0.1, 0.25));
  const auto e = error_of(write_files(ScratchDir("dupconfig"),
                                      "[sweep]\nbase = \"base.toml\"\n[sweep.set]\n"
                                      "\"flow.J\" = 0.1\n[sweep.axes]\n"
                                      "\"output.frame_strain\" = [0.0, " +
                                          frame + "]\n"));
  EXPECT_NE(e.find("run the same configuration"), std::string::npos) << e;
  const ScratchDir scratch;
  const auto dir =
      write_files(scratch, "[sweep]\nbase = \"folder\"\n[sweep.axes]\n\"flow.J\" = [0.1]\n");
  fs::create_directories(dir.parent_path() / "folder");
  EXPECT_NE(error_of(dir).find("is a directory, not a config file"), std::string::npos);
}

TEST(Sweep, FreshAndForeignPointDirectories) {
  const ScratchDir scratch;
  const auto file = write_files(scratch,
                                "[sweep]\nbase = \"base.toml\"\n[sweep.axes]\n"
                                "\"flow.J\" = [0.1, 0.01]\n");
  const auto spec = load_sweep(file);
  const auto points = expand_points(spec);
  const auto out = file.parent_path() / "out";
  EXPECT_EQ(point_state(spec, points[0], out), PointState::fresh);
  // A finished run of the same config is skipped...
  const auto dir = point_dir(out, points[0]);
  fs::create_directories(dir);
  std::ofstream(dir / "config.toml") << to_toml(load_config(spec.base, points[0].overrides));
  EXPECT_EQ(point_state(spec, points[0], out), PointState::fresh);  // started, nothing to keep
  std::ofstream(dir / "checkpoint.bin") << "x";
  EXPECT_EQ(point_state(spec, points[0], out), PointState::resumable);
  std::ofstream(dir / "summary.json") << "{}";
  EXPECT_EQ(point_state(spec, points[0], out), PointState::finished);
  // ...but a finished run of another config in its place is never mixed in, and the refusal
  // names the key that differs.
  std::ofstream(dir / "config.toml") << to_toml(load_config(spec.base, points[1].overrides));
  try {
    point_state(spec, points[0], out);
    ADD_FAILURE() << "a point of another configuration was taken";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("flow.J: 0.01 -> 0.1"), std::string::npos) << e.what();
  }
}

TEST(Sweep, FitsRecoverSyntheticPowerLaws) {
  // Exact laws with the seed's values: every fit must give them back.
  std::vector<nlohmann::json> rows;
  for (double J : {1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2, 1e-1}) {
    const double phi = 0.81 - 0.64 * std::sqrt(J);
    rows.push_back({{"J", J},
                    {"phi", phi},
                    {"mu", 0.3 + 0.9 * std::pow(J, 0.4)},
                    {"D", 0.024 * std::pow(J, -0.25)},
                    {"dv", 0.26 * std::pow(J, -0.25)},
                    {"psi", 0.35 * std::pow(J, 0.25)}});
  }
  const auto f = fit_group(rows);
  EXPECT_NEAR(f["D_vs_J"]["a"].get<double>(), 0.024, 1e-9);
  EXPECT_NEAR(f["D_vs_J"]["b"].get<double>(), -0.25, 1e-9);
  EXPECT_NEAR(f["dv_vs_J"]["b"].get<double>(), -0.25, 1e-9);
  EXPECT_NEAR(f["psi_vs_J"]["a"].get<double>(), 0.35, 1e-9);
  EXPECT_NEAR(f["phi_of_J"]["phi_c"].get<double>(), 0.81, 1e-4);
  EXPECT_NEAR(f["phi_of_J"]["b"].get<double>(), 0.5, 1e-2);
  EXPECT_NEAR(f["mu_of_J"]["mu_c"].get<double>(), 0.3, 1e-3);
  EXPECT_NEAR(f["mu_of_J"]["b"].get<double>(), 0.4, 1e-2);
  // D ~ J^-1/4 and phi_c - phi ~ J^1/2 give D ~ (phi_c - phi)^-1/2.
  EXPECT_NEAR(f["D_vs_phic_minus_phi"]["b"].get<double>(), -0.5, 2e-2);
  EXPECT_NEAR(f["psi_vs_phic_minus_phi"]["b"].get<double>(), 0.5, 2e-2);

  // Too few points: the fit says why instead of inventing numbers.
  rows.resize(2);
  const auto g = fit_group(rows);
  EXPECT_TRUE(g["D_vs_J"].contains("error"));
  EXPECT_TRUE(g["phi_of_J"].contains("error"));
  EXPECT_TRUE(g["D_vs_phic_minus_phi"].contains("error"));
}

TEST(Sweep, OversubscribedPoolIsWarnedAbout) {
  // 2 cores: two single-threaded workers fit, a third or a second thread each does not.
  EXPECT_EQ(oversubscription_warning(2, 1, 2), "");
  EXPECT_EQ(oversubscription_warning(1, 2, 2), "");
  const std::string w = oversubscription_warning(3, 1, 2);
  EXPECT_NE(w.find("--jobs 3 x OMP_THREAD_LIMIT 1 = 3 threads on 2 cores"), std::string::npos) << w;
  EXPECT_NE(w.find("Use --jobs 2"), std::string::npos) << w;
  EXPECT_NE(oversubscription_warning(2, 2, 2).find("Use --jobs 1"), std::string::npos);
}

namespace {

// A finished point: its config and a summary on the law D = 0.024 J^-1/4 (x noise), etc.
void fake_finished(const SweepSpec& spec, const SweepPoint& p, const fs::path& out, double noise) {
  const auto dir = point_dir(out, p);
  fs::create_directories(dir);
  const Config cfg = load_config(spec.base, p.overrides);
  std::ofstream(dir / "config.toml") << to_toml(cfg);
  const double J = cfg.flow.j;
  const nlohmann::json s = {{"J", J},
                            {"seed", cfg.run.seed},
                            {"steady", true},
                            {"phi", 0.81 - 0.64 * std::sqrt(J) + 0.002 * noise},
                            {"mu", 0.3 + 0.9 * std::pow(J, 0.4)},
                            {"D", 0.024 * std::pow(J, -0.25) * (1 + 0.1 * noise)},
                            {"D_err", 0.1},
                            {"dv", 0.26 * std::pow(J, -0.25) * (1 + 0.02 * noise)},
                            {"psi", 0.35 * std::pow(J, 0.25) * (1 + 0.05 * noise)}};
  std::ofstream(dir / "summary.json") << s.dump();
}

}  // namespace

TEST(Sweep, ResultsPersistAndRefitFromTheStoreAlone) {
  const ScratchDir scratch;
  const auto file = write_files(scratch,
                                "[sweep]\nbase = \"base.toml\"\nresults = \"stored\"\n"
                                "[sweep.axes]\n\"flow.J\" = [1e-4, 1e-3, 1e-2, 1e-1]\n"
                                "\"run.seed\" = [1, 2, 3]\n");
  const auto spec = load_sweep(file);
  EXPECT_EQ(spec.results, file.parent_path() / "stored");
  const auto points = expand_points(spec);
  const auto out = file.parent_path() / "out";
  const double noise[] = {-1.0, 0.3, 0.7};
  for (const auto& p : points) fake_finished(spec, p, out, noise[p.index % 3]);
  const auto fits = collect_sweep(spec, out);
  EXPECT_EQ(fits["finished"].get<long>(), 12);
  const auto& f = fits["groups"][0]["fits"];
  // Quoted errors come from the scatter between seeds (bootstrap), the regression's are kept.
  EXPECT_EQ(f["D_vs_J"]["errors"], "seed bootstrap");
  EXPECT_GT(f["D_vs_J"]["a_stderr"].get<double>(), 0.0);
  EXPECT_TRUE(f["D_vs_J"].contains("b_regression_stderr"));
  // The per-J rows hold the seeds' scatter and what the runs' own errors predict for it.
  EXPECT_NEAR(fits["groups"][0]["rows"][0]["D_run_err"].get<double>(), 0.1 / std::sqrt(3.0), 1e-12);
  // Every point is stored; without the run directories the stored points are finished and
  // the same fits come back from the store alone.
  for (const auto& p : points) {
    EXPECT_TRUE(fs::exists(spec.results / "points" / p.name / "summary.json"));
    EXPECT_FALSE(stored_point(spec, p).empty());
  }
  EXPECT_TRUE(fs::exists(spec.results / "fits.json"));
  fs::remove_all(out);
  EXPECT_EQ(point_state(spec, points[0], out), PointState::finished);
  const auto again = collect_sweep(spec, file.parent_path() / "elsewhere");
  EXPECT_EQ(again["groups"], fits["groups"]);
  // A sweep over a part of the store (one J, one seed) stores into it but leaves the store's
  // sweep.csv and fits.json, which stand for all twelve points, as they were.
  const auto read = [](const fs::path& f) {
    std::ifstream in(f);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string store_fits = read(spec.results / "fits.json");
  const std::string store_csv = read(spec.results / "sweep.csv");
  const auto part = file.parent_path() / "part.toml";
  std::ofstream(part) << "[sweep]\nbase = \"base.toml\"\nresults = \"stored\"\n"
                         "[sweep.axes]\n\"flow.J\" = [1e-3]\n\"run.seed\" = [2]\n";
  const auto part_fits = collect_sweep(load_sweep(part), file.parent_path() / "part");
  EXPECT_EQ(part_fits["finished"].get<long>(), 1);
  EXPECT_EQ(read(spec.results / "fits.json"), store_fits);
  EXPECT_EQ(read(spec.results / "sweep.csv"), store_csv);
  EXPECT_TRUE(fs::exists(file.parent_path() / "part" / "fits.json"));
  // A store of another configuration is never reused.
  std::ofstream(spec.results / "points" / points[0].name / "config.toml")
      << to_toml(load_config(spec.base, points[5].overrides));
  try {
    stored_point(spec, points[0]);
    ADD_FAILURE() << "a stored point of another configuration was reused";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(" -> "), std::string::npos) << e.what();
  }
}

// Issue 35, case 4: a sweep over part of the points, collected into the folder of the whole,
// rewrote its sweep.csv and fits.json with that part alone. The folder's other finished points
// stay in both, with their axis values, and the fits come out as the whole sweep's.
TEST(Sweep, APartialSweepKeepsTheFoldersOtherPointsInItsTables) {
  const ScratchDir scratch;
  const auto file = write_files(scratch,
                                "[sweep]\nbase = \"base.toml\"\n"
                                "[sweep.axes]\n\"flow.J\" = [1e-4, 1e-3, 1e-2, 1e-1]\n"
                                "\"run.seed\" = [1, 2, 3]\n");
  const auto spec = load_sweep(file);
  const auto out = file.parent_path() / "out";
  const double noise[] = {-1.0, 0.3, 0.7};
  for (const auto& p : expand_points(spec)) fake_finished(spec, p, out, noise[p.index % 3]);
  const auto whole = collect_sweep(spec, out);
  const auto rows = [&] {
    std::ifstream in(out / "sweep.csv");
    std::string line;
    long n = -1;
    while (std::getline(in, line)) ++n;
    return n;
  };
  ASSERT_EQ(rows(), 12);
  const auto part = file.parent_path() / "part.toml";
  std::ofstream(part) << "[sweep]\nbase = \"base.toml\"\n"
                         "[sweep.axes]\n\"flow.J\" = [1e-3]\n\"run.seed\" = [2]\n";
  const auto again = collect_sweep(load_sweep(part), out);
  EXPECT_EQ(rows(), 12);
  EXPECT_EQ(again["finished"].get<long>(), 12);
  ASSERT_EQ(again["groups"].size(), 1u);
  EXPECT_EQ(again["groups"][0]["fits"], whole["groups"][0]["fits"]);
  EXPECT_EQ(again["groups"][0]["rows"].size(), 4u);
}

// A refit over two stores: the re-measured store (listed first) replaces the older one's J, a
// point whose window failed the stationarity test is left out, and so is an older point whose
// walls' mu differ beyond steady.drift_z (3) combined errors; the fits are the sweep's own.
TEST(Sweep, FitOverStoresTakesEachJFromTheFirstAndDropsDriftingPoints) {
  const ScratchDir scratch;
  const auto old_file = write_files(scratch,
                                    "[sweep]\nbase = \"base.toml\"\nresults = \"old_store\"\n"
                                    "[sweep.axes]\n\"flow.J\" = [1e-4, 1e-3, 1e-2, 1e-1]\n"
                                    "\"run.seed\" = [1, 2]\n");
  const auto root = old_file.parent_path();
  const auto old_spec = load_sweep(old_file);
  for (const auto& p : expand_points(old_spec))
    fake_finished(old_spec, p, root / "old_run", p.index % 2 ? 0.5 : -0.5);
  collect_sweep(old_spec, root / "old_run");
  // An older point without the verdict: walls' mu 0.1 apart with errors 0.02 (z = 3.5).
  const auto drifting = old_spec.results / "points" / "J=0.001_seed=2" / "summary.json";
  nlohmann::json s;
  std::ifstream(drifting) >> s;
  s["mu_top"] = 0.5, s["mu_bottom"] = 0.6, s["mu_top_err"] = 0.02, s["mu_bottom_err"] = 0.0;
  std::ofstream(drifting) << s.dump();
  const auto kept = old_spec.results / "points" / "J=0.001_seed=1" / "summary.json";
  std::ifstream(kept) >> s;
  s["mu_top"] = 0.5, s["mu_bottom"] = 0.55, s["mu_top_err"] = 0.02, s["mu_bottom_err"] = 0.0;
  std::ofstream(kept) << s.dump();

  std::ofstream(root / "new.toml") << "[sweep]\nbase = \"base.toml\"\nresults = \"new_store\"\n"
                                      "[sweep.set]\n\"run.strain\" = 60.0\n"
                                      "[sweep.axes]\n\"flow.J\" = [1e-2, 1e-1]\n"
                                      "\"run.seed\" = [1, 2, 3]\n";
  const auto new_spec = load_sweep(root / "new.toml");
  for (const auto& p : expand_points(new_spec))
    fake_finished(new_spec, p, root / "new_run", 0.3 * static_cast<double>(p.index % 3) - 0.3);
  const auto unsteady = root / "new_run" / "points" / "J=0.1_seed=3" / "summary.json";
  std::ifstream(unsteady) >> s;
  s["stationary"] = false;
  std::ofstream(unsteady) << s.dump();
  collect_sweep(new_spec, root / "new_run");

  const auto out = root / "table1";
  const auto fits = fit_stores({new_spec.results, old_spec.results}, out);
  // Used: old J = 1e-4 (2) and 1e-3 (1 of 2), new J = 1e-2 (3) and 1e-1 (2 of 3).
  EXPECT_EQ(fits["finished"].get<long>(), 8);
  EXPECT_EQ(fits["points"].get<long>(), 14);
  std::map<double, long> runs;
  for (const auto& r : fits["groups"][0]["rows"]) runs[r["J"].get<double>()] = r["runs"];
  EXPECT_EQ(runs, (std::map<double, long>{{1e-4, 2}, {1e-3, 1}, {1e-2, 3}, {1e-1, 2}}));
  std::ifstream csv(out / "sweep.csv");
  const std::string text(std::istreambuf_iterator<char>(csv), {});
  EXPECT_NE(text.find("old_store/J=0.01_seed=1,replaced by"), std::string::npos) << text;
  EXPECT_NE(text.find("old_store/J=0.001_seed=2,\"done, drifting (mu_top - mu_bottom)\""),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("new_store/J=0.1_seed=3,\"done, not stationary\""), std::string::npos);
  // As a sensitivity check the flagged points can enter the fits: 2 more, the replaced never.
  const auto all = fit_stores({new_spec.results, old_spec.results}, root / "table1_all", true);
  EXPECT_EQ(all["finished"].get<long>(), 10);
  EXPECT_TRUE(all["includes_not_stationary"].get<bool>());
  // Its own folder only: a store's or a sweep's fits are never replaced.
  EXPECT_THROW(fit_stores({new_spec.results}, old_spec.results), ConfigError);
  EXPECT_NO_THROW(fit_stores({new_spec.results}, out));  // its own earlier output
  // Stores of other physics are not one group.
  std::ofstream(root / "stiff.toml") << "[sweep]\nbase = \"base.toml\"\nresults = \"stiff\"\n"
                                        "[sweep.set]\n\"contact.ktilde\" = 1e5\n"
                                        "[sweep.axes]\n\"flow.J\" = [1e-3]\n";
  const auto stiff = load_sweep(root / "stiff.toml");
  for (const auto& p : expand_points(stiff)) fake_finished(stiff, p, root / "stiff_run", 0.0);
  collect_sweep(stiff, root / "stiff_run");
  try {
    fit_stores({stiff.results, old_spec.results}, root / "mixed");
    ADD_FAILURE() << "stores of two stiffnesses were fitted as one";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("not one group"), std::string::npos) << e.what();
  }
}

// The seeds' bootstrap quotes the unbiased standard error even with two seeds per J. Three J
// (1e-3, 1e-2, 1e-1) on an exact D = J^-1/4, two seeds each; only J = 0.1 scatters, by
// D (1 +- eps). The log-log slope through three equally spaced points is (y_3 - y_1) / 2, so its
// error is that of log10 of the J = 0.1 mean over 2: s.e.m. of that mean = eps D (unbiased:
// s^2/n = 2 eps^2 D^2 / 2), hence sd(b) = eps / (2 ln 10). The plain bootstrap would give 1/sqrt(2)
// of it (0.71): the tolerance (5 %) is the sampling error of 2000 replicates, several times over.
TEST(Sweep, SeedBootstrapQuotesTheUnbiasedErrorWithTwoSeeds) {
  const double eps = 0.01;
  std::map<double, std::vector<nlohmann::json>> by_j;
  for (double J : {1e-3, 1e-2, 1e-1}) {
    const double d = std::pow(J, -0.25);
    for (double sign : {+1.0, -1.0}) {
      const double f = J == 1e-1 ? 1.0 + sign * eps : 1.0;
      by_j[J].push_back({{"phi", 0.8 - 0.6 * std::sqrt(J)},
                         {"mu", 0.3 + J},
                         {"D", d * f},
                         {"dv", 0.3 * d},
                         {"psi", 0.3 / d}});
    }
  }
  const auto boot = seed_bootstrap(by_j, 2000);
  const double want = eps / (2.0 * std::log(10.0));
  ASSERT_TRUE(boot.contains("D_vs_J"));
  EXPECT_NEAR(boot["D_vs_J"]["b"].get<double>(), want, 0.05 * want);
  // dv did not scatter: no error there.
  EXPECT_LT(boot["dv_vs_J"]["b"].get<double>(), 1e-12);
}

TEST(Sweep, ASweepOfSeedsOnlyStoresItsPointsWithoutJFits) {
  // Channel cases are swept over seeds: their summaries have no J, so the collected fits.json
  // has no groups and does not repeat the shear paper's Table 1, while every point is stored.
  const ScratchDir scratch;
  const auto file = write_files(scratch,
                                "[sweep]\nbase = \"base.toml\"\nresults = \"stored\"\n"
                                "[sweep.axes]\n\"run.seed\" = [1, 2]\n");
  const auto spec = load_sweep(file);
  const auto out = file.parent_path() / "out";
  for (const auto& p : expand_points(spec)) {
    const auto dir = point_dir(out, p);
    fs::create_directories(dir);
    std::ofstream(dir / "config.toml") << to_toml(load_config(spec.base, p.overrides));
    std::ofstream(dir / "summary.json") << R"({"channel_u_c": 1.4, "steady": true})";
  }
  const auto fits = collect_sweep(spec, out);
  EXPECT_EQ(fits["finished"].get<long>(), 2);
  EXPECT_TRUE(fits["groups"].empty());
  EXPECT_FALSE(fits.contains("seed_table1"));
  EXPECT_TRUE(fs::exists(spec.results / "points" / "seed=2" / "summary.json"));
}
