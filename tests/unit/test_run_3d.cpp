// A run of spheres (scene.dimension = 3) through the same run as the discs: the configuration
// selects it, the pressure cell of spheres carries P Lx Lz on its floating wall at every held
// step, the observers measure phi as a volume fraction, the trajectory holds 3D frames and a
// 3 x 3 box, and a run extended from its end state (its trajectory cut back and continued) is
// the longer run to the bit (the checkpoint holds the spheres' whole state: positions,
// unwrapped positions, tangential spring vectors, the observers' accumulators).
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "scratch_dir.hpp"
#include "sheardiff/config.hpp"
#include "sheardiff/engine.hpp"
#include "sheardiff/integrator/stress.hpp"
#include "sheardiff/io/h5md.hpp"
#include "sheardiff/io/summary_keys.hpp"
#include "sheardiff/observe/diffusion_observer.hpp"
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
  c.particles.phi_init_spheres = 0.0;  // the loose lattice: 4 x 4 sites per layer, 4 layers
  c.flow.j = 3e-2;
  c.contact.ktilde = 1e3;
  c.run.strain = strain;
  c.run.seed = 5;
  c.steady.window = 0.3;
  c.output.frame_strain = 0.02;
  c.output.checkpoint_strain = 0.25;
  c.analysis.msd_window_lo = 0.05;
  c.analysis.msd_window_hi = 0.2;
  c.analysis.vacf_max_lag = 0.2;
  c.analysis.error_block = 0.1;
  return c;
}

std::vector<hsize_t> shape(hid_t file, const std::string& name) {
  const hid_t ds = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
  const hid_t space = H5Dget_space(ds);
  std::vector<hsize_t> dims(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  H5Sclose(space);
  H5Dclose(ds);
  return dims;
}

// H5MD of spheres: (frames, N, 3) positions, velocities, angular velocities and image counts,
// and a 3 x 3 box whose last row is (0, 0, lz), periodic in x and z.
void expect_trajectory_of_spheres(const fs::path& file, const nlohmann::json& js) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  const std::string g = "/particles/suspension/";
  const std::vector<hsize_t> pos = shape(f, g + "position/value");
  ASSERT_EQ(pos.size(), 3u);
  const hsize_t frames = pos[0], n = pos[1];
  EXPECT_GT(frames, 10u);
  EXPECT_EQ(pos[2], 3u);
  EXPECT_EQ(n, js[summary_key::N].get<hsize_t>() + 2 * 36);  // 6 x 6 spheres in each wall
  for (const char* e : {"velocity/value", "angular_velocity/value", "image/value"})
    EXPECT_EQ(shape(f, g + e), (std::vector<hsize_t>{frames, n, 3})) << e;
  EXPECT_EQ(shape(f, g + "box/edges/value"), (std::vector<hsize_t>{frames, 3, 3}));
  const auto read = [&](const std::string& name, hid_t type, auto& out) {
    const hid_t ds = H5Dopen2(f, (g + name).c_str(), H5P_DEFAULT);
    H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
    H5Dclose(ds);
  };
  std::vector<double> edges(9 * frames), position(3 * n * frames);
  std::vector<int> image(3 * n * frames);
  read("box/edges/value", H5T_NATIVE_DOUBLE, edges);
  read("position/value", H5T_NATIVE_DOUBLE, position);
  read("image/value", H5T_NATIVE_INT, image);
  H5Fclose(f);
  const double* last = &edges[9 * (frames - 1)];
  EXPECT_EQ(last[0], js[summary_key::lx].get<double>());
  EXPECT_EQ(last[8], last[0]);  // lz = lx
  for (int k : {1, 2, 5, 6, 7}) EXPECT_EQ(last[k], 0.0) << k;
  // position + image . edges is continuous: no sphere moves half a cell between two frames
  // 0.02 strain apart (the spheres near the top wall cross x several times in the run).
  double largest_jump = 0.0;
  int crossings = 0;
  for (hsize_t t = 1; t < frames; ++t)
    for (hsize_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        const auto at = [&](hsize_t frame) {
          const hsize_t k = 3 * (n * frame + i);
          const double* e = &edges[9 * frame];
          return position[k + c] + image[k] * e[c] + image[k + 1] * e[3 + c] +
                 image[k + 2] * e[6 + c];
        };
        largest_jump = std::max(largest_jump, std::abs(at(t) - at(t - 1)));
        crossings += image[3 * (n * t + i) + c] != image[3 * (n * (t - 1) + i) + c];
      }
  EXPECT_GT(crossings, 0);
  EXPECT_LT(largest_jump, 0.25 * last[0]);
}

// The contact network of the last frame against that frame's positions: every listed pair
// overlaps; the tangential spring force on j is a vector in the plane normal to n (to round-off:
// the spring was turned into that plane at these positions) within Coulomb's cone, and on it for
// the sliding contacts (a tangential force of the wrong stiffness scale would leave the cone's
// surface).
void expect_contacts_of_spheres(const fs::path& file, double mu) {
  const ContactNetwork c = read_h5md_contacts(file, -1);
  ASSERT_EQ(c.components, 3);
  ASSERT_GT(c.pairs.size(), 20u);
  ASSERT_EQ(c.tangential_force.size(), 3 * c.pairs.size());
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  const std::string g = "/particles/suspension/";
  const std::vector<hsize_t> pos = shape(f, g + "position/value");
  const hsize_t frames = pos[0], n = pos[1];
  std::vector<double> edges(9 * frames), position(3 * n * frames), diameter(n);
  for (const auto& [name, out] : {std::pair<std::string, double*>{"box/edges/value", edges.data()},
                                  {"position/value", position.data()},
                                  {"diameter", diameter.data()}}) {
    const hid_t ds = H5Dopen2(f, (g + name).c_str(), H5P_DEFAULT);
    H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out);
    H5Dclose(ds);
  }
  H5Fclose(f);
  const double lx = edges[9 * (frames - 1)], lz = edges[9 * (frames - 1) + 8];
  const double* x = &position[3 * n * (frames - 1)];
  int sliding = 0, loaded = 0;
  for (std::size_t k = 0; k < c.pairs.size(); ++k) {
    const auto [i, j] = c.pairs[k];
    Space3 d(x[3 * j] - x[3 * i], x[3 * j + 1] - x[3 * i + 1], x[3 * j + 2] - x[3 * i + 2]);
    d.x() -= lx * std::round(d.x() / lx);  // periodic in x and z, walls in y
    d.z() -= lz * std::round(d.z() / lz);
    const double overlap = 0.5 * (diameter[i] + diameter[j]) - d.norm();
    EXPECT_GT(overlap, 0.0) << "contact " << k;
    const double fn = c.normal_force[k];
    const Space3 ft(c.tangential_force[3 * k], c.tangential_force[3 * k + 1],
                    c.tangential_force[3 * k + 2]);
    EXPECT_GT(fn, 0.0) << "contact " << k;
    EXPECT_LE(std::abs(ft.dot(d.normalized())), 1e-9 * (fn + ft.norm())) << "contact " << k;
    EXPECT_LE(ft.norm(), mu * fn * (1.0 + 1e-9)) << "contact " << k;
    if (c.sliding[k] != 0) {
      ++sliding;
      EXPECT_NEAR(ft.norm(), mu * fn, 1e-9 * fn) << "sliding contact " << k;
    }
    loaded += ft.norm() > 1e-3 * fn;
  }
  EXPECT_GT(sliding, 0) << "no sliding contact: the Coulomb check had nothing to test";
  EXPECT_GT(loaded, static_cast<int>(c.pairs.size()) / 4) << "the tangential springs carry load";
}

TEST(SphereRun, ConfigurationSelectsTheSpheresAndTheirOwnChecks) {
  const std::string base = "[scene]\ntype = \"pressure_shear\"\ndimension = 3\n";
  const Config c = parse_config(base, "t.toml");
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
  refused("[scene]\ntype = \"channel\"\ndimension = 3\n", "scene.dimension");
  refused("[scene]\ntype = \"simple_shear\"\ndimension = 3\n[particles]\nphi_init_spheres = 0\n",
          "particles.phi_init_spheres");
  refused("[scene]\ntype = \"pressure_shear\"\ndimension = 4\n", "scene.dimension");
  // A cell of 8 spheres (2 x 2 sites, 3 d wide) is narrower than two neighbour cut-offs.
  Config narrow = c;
  narrow.particles.n = 8;
  EXPECT_THROW(validate_run_inputs(narrow, "t.toml"), ConfigError);
}

// A config file of spheres that does not name contact.sliding_stiffness runs "sideways"; one of
// discs (the same law either way) and a code-built Config keep "none". A run's record that does
// not name the key was written before it existed and ran "none": it still reads as that run, so
// a resume or an extension of it with "none" goes on, and one with the new default is refused
// naming the key, never switched silently.
TEST(SphereRun, AFileOfSpheresSlidesSidewaysAndARecordKeepsTheLawItRan) {
  const std::string spheres = "[scene]\ntype = \"pressure_shear\"\ndimension = 3\n";
  EXPECT_EQ(parse_config(spheres, "t.toml").contact.sliding_stiffness, "sideways");
  EXPECT_EQ(
      parse_config("[scene]\ntype = \"pressure_shear\"\n", "t.toml").contact.sliding_stiffness,
      "none");
  EXPECT_EQ(parse_config(spheres + "[contact]\nsliding_stiffness = \"none\"\n", "t.toml")
                .contact.sliding_stiffness,
            "none");
  EXPECT_EQ(
      parse_config(spheres, "t.toml", {"contact.sliding_stiffness=none"}).contact.sliding_stiffness,
      "none");
  // Discs given as spheres by an override take the spheres' default.
  EXPECT_EQ(parse_config("[scene]\ntype = \"pressure_shear\"\n", "t.toml", {"scene.dimension=3"})
                .contact.sliding_stiffness,
            "sideways");
  EXPECT_EQ(parse_config(spheres, "t.toml", {}, ConfigSource::record).contact.sliding_stiffness,
            "none");

  const ScratchDir dir;
  Config old = sphere_cell(0.6);
  ASSERT_EQ(old.contact.sliding_stiffness, "none");
  run_to_directory(old, dir, false);
  // What a sheardiff older than the key wrote: the same record without its line.
  std::string record;
  {
    std::ifstream in(dir / "config.toml");
    std::stringstream ss;
    ss << in.rdbuf();
    record = ss.str();
  }
  const std::string line = "sliding_stiffness = \"none\"\n";
  ASSERT_NE(record.find(line), std::string::npos);
  record.erase(record.find(line), line.size());
  std::ofstream(dir / "config.toml") << record;
  Config switched = sphere_cell(0.7);
  switched.contact.sliding_stiffness = "sideways";
  try {
    run_to_directory(switched, dir, false, true);
    ADD_FAILURE() << "an extension with another sliding law was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("contact.sliding_stiffness"), std::string::npos)
        << e.what();
  }
  const nlohmann::json extended = run_to_directory(sphere_cell(0.7), dir, false, true);
  EXPECT_GE(extended[summary_key::strain].get<double>(), 0.7 - 1e-9);
}

TEST(SphereRun, PressureCellOfSpheresCarriesTheLoadAndMeasuresAVolumeFraction) {
  const ScratchDir dir;
  Config cfg = sphere_cell(1.5);
  cfg.output.contacts = true;
  const nlohmann::json js = run_to_directory(cfg, dir, false);
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
  expect_trajectory_of_spheres(dir / "trajectory.h5", js);
  expect_contacts_of_spheres(dir / "trajectory.h5", cfg.contact.mu);
}

// Simple shear of spheres (scene/simple_shear.cpp): 100 spheres at volume fraction 0.45 in a
// Lees-Edwards cube, J = 1e-2, ktilde = 1e3, one strain.
TEST(SphereRun, SimpleShearOfSpheresInALeesEdwardsCube) {
  const ScratchDir dir;
  Config c;
  c.scene.type = "simple_shear";
  c.scene.dimension = 3;
  c.particles.n = 100;
  c.particles.phi_init_spheres = 0.45;
  c.flow.j = 1e-2;
  c.contact.ktilde = 1e3;
  c.run.strain = 1.0;
  c.run.transient_strain = 0.3;
  c.run.seed = 3;
  c.output.frame_strain = 0.02;
  // The diffusion analysis over the 0.7 measured strains, sampled at the frames.
  c.analysis.sample_strain = c.output.frame_strain;
  c.analysis.msd_window_lo = 0.05;
  c.analysis.msd_window_hi = 0.2;
  c.analysis.vacf_max_lag = 0.2;
  c.analysis.error_block = 0.1;
  const nlohmann::json js = run_to_directory(c, dir, false);
  EXPECT_EQ(js[summary_key::dimension].get<int>(), 3);
  // The cell holds its volume fraction: the spheres' volume over lx ly lz.
  EXPECT_NEAR(js[summary_key::phi].get<double>(), 0.45, 1e-12);
  // Sheared: a positive shear stress and particle pressure; overlaps ~ 1/ktilde (a contact
  // carrying ~ P d^2 at P ~ sigma_xy / mu overlaps by ~ 1e-3 d here; measured 3.4e-3 d at most).
  EXPECT_GT(js[summary_key::shear_stress].get<double>(), 0.0);
  EXPECT_GT(js[summary_key::pressure].get<double>(), 0.0);
  EXPECT_LT(js[summary_key::max_overlap].get<double>(), 1e-2);

  const hid_t f = H5Fopen((dir / "trajectory.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  const std::string g = "/particles/suspension/";
  const std::vector<hsize_t> pos = shape(f, g + "position/value");
  ASSERT_EQ(pos.size(), 3u);
  const hsize_t frames = pos[0], n = pos[1];
  ASSERT_EQ(n, 100u);  // no walls
  std::vector<double> edges(9 * frames), position(3 * n * frames), velocity(3 * n * frames),
      diameter(n);
  for (auto [name, out] :
       {std::pair{"box/edges/value", &edges}, std::pair{"position/value", &position},
        std::pair{"velocity/value", &velocity}, std::pair{"diameter", &diameter}}) {
    const hid_t ds = H5Dopen2(f, (g + name).c_str(), H5P_DEFAULT);
    H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out->data());
    H5Dclose(ds);
  }
  H5Fclose(f);
  const double lx = edges[0], ly = edges[4], gammadot = c.flow.j;
  double sxy = 0, syy = 0, sy = 0, sx = 0, count = 0;
  for (hsize_t t = 0; t < frames; ++t) {
    const double* e = &edges[9 * t];
    // The box: (lx, 0, 0), (tilt, ly, 0), (0, 0, lz) with the Lees-Edwards tilt gammadot t ly
    // (frames every 0.02 strain), kept by the writer in [-lx/2, lx/2]. A tilt is defined up to
    // a multiple of lx (the same lattice): at strain 0.5 of this cube the two ends +-lx/2 are one
    // rounding of the accumulated strain apart, so the tilt is compared modulo lx.
    const double strain = 0.02 * static_cast<double>(t);
    const double tilt = strain * ly;
    EXPECT_NEAR(std::remainder(e[3] - tilt, lx), 0.0, 1e-9) << "frame " << t;
    EXPECT_LE(std::abs(e[3]), 0.5 * lx + 1e-9) << "frame " << t;
    EXPECT_EQ(e[8], lx);
    // Every pair force acts on both its spheres, across the Lees-Edwards faces too, and nothing
    // else pushes the periodic cell: the drags, 3 pi eta d (u - gammadot y x), sum to zero over
    // the spheres (round-off: measured 1e-14 of the summed magnitudes).
    Space3 drag = Space3::Zero(), scale = Space3::Zero();
    for (hsize_t i = 0; i < n; ++i) {
      const hsize_t k = 3 * (n * t + i);
      Space3 rel(velocity[k] - gammadot * position[k + 1], velocity[k + 1], velocity[k + 2]);
      drag += diameter[i] * rel;
      scale += diameter[i] * rel.cwiseAbs();
      if (t == 0) continue;
      const double y = position[k + 1] - 0.5 * ly;
      sx += velocity[k] * y, sy += y, syy += y * y, sxy += velocity[k], count += 1;
    }
    if (t > 0) {
      for (int a = 0; a < 3; ++a) EXPECT_LT(std::abs(drag[a]), 1e-10 * scale[a]) << t;
    }
  }
  // The spheres follow the imposed flow on average: the slope of u_x over y is gammadot (the
  // cell is homogeneous; measured within 5 % in three seeds of this cell, the fluctuations of
  // 100 spheres over 50 correlated frames).
  const double slope = (sx - sy * sxy / count) / (syy - sy * sy / count);
  EXPECT_NEAR(slope / gammadot, 1.0, 0.1);
  // `analyse` recomputes the analysis from the frames of spheres (y unwrapped through the image
  // counts of a Lees-Edwards box): sampled at the frames, the run's own numbers.
  ASSERT_TRUE(js.contains(summary_key::psi)) << js.dump(1);
  const Reanalysis re = reanalyse_run(dir);
  EXPECT_TRUE(re.differs.empty()) << fmt::format("{}", fmt::join(re.differs, ", "));
  EXPECT_EQ(re.folder, dir.path());
  for (const char* key : {summary_key::D, summary_key::dv, summary_key::psi})
    EXPECT_NEAR(re.summary[key].get<double>(), js[key].get<double>(),
                1e-9 * std::abs(js[key].get<double>()))
        << key;
}

// With either sliding law: "sideways" reads each contact's last cap ratio, which the
// checkpoint must carry (layout 8) for the extension to stay on the longer run's trajectory.
TEST(SphereRun, ExtendedRunOfSpheresIsTheLongerRunToTheBit) {
  const ScratchDir root;
  for (const char* sliding : {"none", "sideways"}) {
    SCOPED_TRACE(sliding);
    fs::remove_all(root);
    const auto cell = [&](double strain) {
      Config c = sphere_cell(strain);
      c.contact.sliding_stiffness = sliding;
      return c;
    };
    const nlohmann::json direct = run_to_directory(cell(1.2), root / "direct", false);
    run_to_directory(cell(0.6), root / "ext", false);
    const nlohmann::json extended = run_to_directory(cell(1.2), root / "ext", false, true);
    for (const char* key :
         {summary_key::steps, summary_key::strain, summary_key::H, summary_key::phi,
          summary_key::shear_stress, summary_key::max_overlap, summary_key::factorisations})
      EXPECT_EQ(extended[key], direct[key]) << key;
  }
}

}  // namespace
}  // namespace sheardiff
