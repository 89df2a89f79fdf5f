// A run of spheres (scene.dimension = 3) through the same run as the discs: the configuration
// selects it, the pressure cell of spheres carries P Lx Lz on its floating wall at every held
// step, the observers measure phi as a volume fraction, and a run extended from its end state
// is the longer run to the bit (the checkpoint holds the spheres' whole state: positions,
// unwrapped positions, tangential spring vectors, the observers' accumulators).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "sheardiff/config.hpp"
#include "sheardiff/engine.hpp"
#include "sheardiff/integrator/stress.hpp"
#include "sheardiff/io/summary_keys.hpp"
#include "sheardiff/run.hpp"

namespace sheardiff {
namespace {

namespace fs = std::filesystem;

// 64 spheres (4 x 4 sites per layer, 4 layers) compacting and sheared at J = 3e-2: a few
// thousand steps.
Config sphere_cell(double strain) {
  Config c;
  c.scene.type = "pressure_shear";
  c.scene.dimension = 3;
  c.particles.n = 64;
  c.flow.j = 3e-2;
  c.contact.ktilde = 1e3;
  c.run.strain = strain;
  c.run.seed = 5;
  c.steady.window = 0.3;
  c.output.trajectory = false;
  c.output.frame_strain = 0.02;
  c.output.checkpoint_strain = 0.25;
  c.analysis.msd_window_lo = 0.05;
  c.analysis.msd_window_hi = 0.2;
  c.analysis.vacf_max_lag = 0.2;
  c.analysis.error_block = 0.1;
  return c;
}

TEST(SphereRun, ConfigurationSelectsTheSpheresAndTheirOwnChecks) {
  const std::string base = "[scene]\ntype = \"pressure_shear\"\ndimension = 3\n";
  const Config c = parse_config(base + "[output]\ntrajectory = false\n", "t.toml");
  EXPECT_EQ(c.scene.dimension, 3);
  validate_run_inputs(c, "t.toml");
  // Each refusal names the key and what is allowed.
  const auto refused = [&](const std::string& text, const std::string& key) {
    try {
      parse_config(text, "t.toml");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  refused(base, "output.trajectory");
  refused("[scene]\ntype = \"simple_shear\"\ndimension = 3\n[output]\ntrajectory = false\n",
          "scene.dimension");
  refused("[scene]\ntype = \"pressure_shear\"\ndimension = 4\n", "scene.dimension");
  // A cell of 8 spheres (2 x 2 sites, 3 d wide) is narrower than two neighbour cut-offs.
  Config narrow = c;
  narrow.particles.n = 8;
  EXPECT_THROW(validate_run_inputs(narrow, "t.toml"), ConfigError);
}

TEST(SphereRun, PressureCellOfSpheresCarriesTheLoadAndMeasuresAVolumeFraction) {
  const fs::path dir = fs::temp_directory_path() / "sheardiff_test_sphere_run";
  fs::remove_all(dir);
  const nlohmann::json js = run_to_directory(sphere_cell(1.5), dir, false);
  EXPECT_EQ(js[summary_key::dimension].get<int>(), 3);
  EXPECT_EQ(js[summary_key::N].get<int>(), 64);
  // Wall force = P Lx Lz at every step the packing holds the wall (the solve's balance, 1e-9).
  EXPECT_LT(js[summary_key::pressure_max_relative_error].get<double>(), 1e-9);
  EXPECT_LT(js[summary_key::wall_free_fall_steps].get<long>(), js[summary_key::steps].get<long>());
  // A volume fraction of spheres between walls: above the loose lattice's ~0.2, below random
  // close packing (0.64); an area fraction of the same packing would exceed 0.8.
  const double phi = js[summary_key::phi].get<double>();
  EXPECT_GT(phi, 0.25);
  EXPECT_LT(phi, 0.64);
  // Overlaps ~ 1/ktilde: a contact carrying a force ~ P d^2 overlaps by P d / kn = 1e-3 d; the
  // mean over the measured contacts stays within a few of that (measured: 2.1e-3 d).
  EXPECT_LT(js[summary_key::mean_overlap].get<double>(), 5e-3);
  EXPECT_TRUE(std::isfinite(js[summary_key::shear_stress].get<double>()));
  fs::remove_all(dir);
}

TEST(SphereRun, ExtendedRunOfSpheresIsTheLongerRunToTheBit) {
  const fs::path root = fs::temp_directory_path() / "sheardiff_test_sphere_extend";
  fs::remove_all(root);
  const nlohmann::json direct = run_to_directory(sphere_cell(1.2), root / "direct", false);
  run_to_directory(sphere_cell(0.6), root / "ext", false);
  const nlohmann::json extended = run_to_directory(sphere_cell(1.2), root / "ext", false, true);
  for (const char* key :
       {summary_key::steps, summary_key::strain, summary_key::H, summary_key::phi,
        summary_key::shear_stress, summary_key::max_overlap, summary_key::factorisations})
    EXPECT_EQ(extended[key], direct[key]) << key;
  fs::remove_all(root);
}

}  // namespace
}  // namespace sheardiff
