// Initial configurations: random placement (non-overlapping, seeded, right mixture) and
// reading a plain table or a frame of an earlier run's H5MD file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "scratch_dir.hpp"
#include "sheardiff/io/h5md.hpp"
#include "sheardiff/run.hpp"
#include "sheardiff/setup/random_packing.hpp"

namespace sheardiff {
namespace {

double max_overlap(const Packing& pk) {
  double worst = 0.0;
  for (std::size_t i = 0; i < pk.position.size(); ++i)
    for (std::size_t j = i + 1; j < pk.position.size(); ++j) {
      Vec2 d = pk.position[j] - pk.position[i];
      d.x() -= pk.lx * std::round(d.x() / pk.lx);
      d.y() -= pk.ly * std::round(d.y() / pk.ly);
      worst = std::max(worst, pk.radius[i] + pk.radius[j] - d.norm());
    }
  return worst;
}

TEST(InitialConfiguration, RandomPackingHasTargetFractionAndNoOverlap) {
  for (double phi : {0.4, 0.7, 0.8}) {
    const Packing pk = random_packing(300, MixRule::Area, 1.4, phi, 1.0, 42);
    double area = 0.0;
    for (double a : pk.radius) area += kPi * a * a;
    EXPECT_NEAR(area / (pk.lx * pk.ly), phi, 1e-12);
    // RSA is exact; compressed packings are relaxed to overlaps below 1e-4 d.
    EXPECT_LT(max_overlap(pk), 1e-4) << "phi " << phi;
  }
}

TEST(InitialConfiguration, MixRules) {
  // Equal area: N_small / N_large = 1.4^2 = 1.96; equal volume: 1.4^3; equal number: 1.
  const auto count_large = [](const std::vector<int>& s) {
    return std::count(s.begin(), s.end(), 1);
  };
  EXPECT_EQ(count_large(bidisperse_species(296, MixRule::Area, 1.4)), 100);
  EXPECT_EQ(count_large(bidisperse_species(1000, MixRule::Number, 1.4)), 500);
  EXPECT_EQ(count_large(bidisperse_species(3744, MixRule::Volume, 1.4)), 1000);
}

TEST(InitialConfiguration, SeededAndReproducible) {
  const Packing a = random_packing(100, MixRule::Area, 1.4, 0.6, 1.0, 7);
  const Packing b = random_packing(100, MixRule::Area, 1.4, 0.6, 1.0, 7);
  const Packing c = random_packing(100, MixRule::Area, 1.4, 0.6, 1.0, 8);
  EXPECT_EQ(a.position, b.position);
  EXPECT_NE(a.position, c.position);
}

TEST(InitialConfiguration, FromTableAndFromH5mdFrame) {
  const ScratchDir dir;
  // A table of 4 discs far apart in a cell given by phi_init.
  {
    std::ofstream t(dir / "start.txt");
    t << "# x y diameter\n1 1 1\n4 1 1.4\n1 4 1\n4 4 1.4\n";
  }
  Config c;
  c.particles.n = 4;
  c.particles.phi_init = 0.2;
  c.particles.init_file = (dir / "start.txt").string();
  c.run.strain = 0.2;
  c.output.frame_strain = 0.1;
  c.analysis.diffusion = false;
  const Scene sc = build_scene(c);
  ASSERT_EQ(sc.particles.n_mobile, 4u);
  EXPECT_EQ(sc.particles.position[1], Vec2(4, 1));
  EXPECT_DOUBLE_EQ(sc.particles.radius[1], 0.7);
  EXPECT_EQ(sc.particles.species[1], 1);
  const double area = kPi * (2 * 0.25 + 2 * 0.49);
  EXPECT_NEAR(area / (sc.box.lx * sc.box.ly), 0.2, 1e-12);

  // Run it, then restart from the last frame of its trajectory.
  run_to_directory(c, dir / "run", false);
  const H5mdFrame last = read_h5md_frame(dir / "run" / "trajectory.h5", -1);
  Config again = c;
  again.particles.init_file = (dir / "run" / "trajectory.h5").string();
  const Scene sc2 = build_scene(again);
  ASSERT_EQ(sc2.particles.position.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(sc2.particles.position[i], last.position[i]);
  EXPECT_EQ(sc2.box.lx, last.lx);

  // A file with the wrong number of particles is refused, naming the key.
  again.particles.n = 5;
  try {
    build_scene(again);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("particles.N"), std::string::npos) << e.what();
  }
}

// Two discs at one spot stopped the run at step 0 with advice about integrator settings (issue
// 35, case 10). Coincident discs, and discs overlapping across the periodic edge, are refused as
// bad input naming the pair; a run's own overlaps (~1/ktilde) are not.
TEST(InitialConfiguration, OverlappingDiscsInAFileAreRefused) {
  const ScratchDir dir;
  Config c;
  c.particles.n = 4;
  c.particles.phi_init = 0.2;  // Lx = Ly = 4.82 d
  c.particles.init_file = (dir / "start.txt").string();
  const auto refused = [&](const std::string& table, const std::string& pair) {
    { std::ofstream(dir / "start.txt") << table; }
    try {
      validate_run_inputs(c, "test");
      ADD_FAILURE() << "accepted:\n" << table;
    } catch (const ConfigError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("particles.init_file"), std::string::npos) << m;
      EXPECT_NE(m.find(pair), std::string::npos) << m;
    }
  };
  refused("1 1 1\n4 1 1.4\n1 4 1\n1 4 1\n", "particles 2 and 3");
  // x = 0.1 and 4.47 are 0.45 d apart through the periodic edge.
  refused("0.1 1 1\n2.5 1 1.4\n4.47 1 1\n2.5 3.5 1.4\n", "particles 0 and 2");
  // A GSD file (the export's format) is named as such, not parsed as a table (issue 34).
  c.particles.init_file = (dir / "start.gsd").string();
  { std::ofstream(dir / "start.gsd") << "binary"; }
  try {
    validate_run_inputs(c, "test");
    ADD_FAILURE() << "a GSD file was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("a GSD file is not read"), std::string::npos) << e.what();
  }
  c.particles.init_file = (dir / "start.txt").string();
  // Touching with a 1 % overlap (a dense run's last frame) is a start.
  { std::ofstream(dir / "start.txt") << "1 1 1\n1.99 1 1\n1 3 1.4\n3 3 1.4\n"; }
  EXPECT_NO_THROW(validate_run_inputs(c, "test"));
}

}  // namespace
}  // namespace sheardiff
