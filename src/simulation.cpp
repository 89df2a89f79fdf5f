#include "sheardiff/simulation.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>

#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/checkpoint_file.hpp"
#include "sheardiff/io/h5md.hpp"
#include "sheardiff/io/hdf5_diagnostics.hpp"
#include "sheardiff/io/io_error.hpp"
#include "sheardiff/io/run_directory.hpp"
#include "sheardiff/io/text.hpp"
#include "sheardiff/observe/diffusion_observer.hpp"
#include "sheardiff/observe/observer.hpp"
#include "sheardiff/observe/pressure_cell.hpp"
#include "sheardiff/observe/run_health.hpp"
#include "sheardiff/observe/stress.hpp"
#include "sheardiff/setup/random_packing.hpp"
#include "sheardiff/version.hpp"

namespace sheardiff {

double interaction_range_factor(const Config& cfg) {
  return PairLaws::from(cfg).range_factor();
}

double explicit_stability_dt(const Config& cfg) {
  return PairLaws::from(cfg).explicit_stability_dt();
}

bool rotational_unknowns(const Config& cfg) {
  // Without a law that couples rotation to translation, omega = omega_inf + T_ext / drag.
  return cfg.solver.rotations == "always" || PairLaws::from(cfg).needs_rotations();
}

void validate_run_inputs(const Config& cfg, const std::string& origin) {
  if (cfg.integrator.type != IntegratorType::Implicit && cfg.integrator.dt > 0.0) {
    const double limit = explicit_stability_dt(cfg);
    if (cfg.integrator.dt >= limit)
      throw ConfigError(fmt::format(
          "{}: integrator.dt: fixed dt = {} is not below the stability limit 2 R/k = {:.3g} "
          "eta/P of explicit springs (smallest pair, normal and slip modes, "
          "docs/model.md section 7; integrator.type = \"{}\", contact.ktilde = {}); use "
          "integrator.dt < "
          "{:.3g}, integrator.dt = 0 (adaptive), or "
          "integrator.type = \"implicit\"",
          origin, cfg.integrator.dt, limit, to_string(cfg.integrator.type), cfg.contact.ktilde,
          limit));
  }
  double lx = 0.0, ly = 0.0, amax = 0.5 * std::max(1.0, cfg.particles.size_ratio);
  if (!cfg.particles.init_file.empty()) {
    try {
      const Packing pk = initial_packing(cfg);
      lx = pk.lx, ly = pk.ly;
      for (double a : pk.radius) amax = std::max(amax, a);
    } catch (const ConfigError& e) {
      throw ConfigError(fmt::format("{}: {}", origin, e.what()));
    } catch (const std::exception& e) {
      throw ConfigError(fmt::format("{}: particles.init_file: {}", origin, e.what()));
    }
  } else {
    // The cell random_packing makes, without placing anything.
    double area = 0.0;
    for (int s : bidisperse_species(cfg.particles.n, cfg.particles.mix, cfg.particles.size_ratio)) {
      const double a = s == 0 ? 0.5 : 0.5 * cfg.particles.size_ratio;
      area += kPi * a * a;
    }
    lx = std::sqrt(area / cfg.particles.phi_init / cfg.particles.aspect);
    ly = cfg.particles.aspect * lx;
  }
  // The neighbour list holds one image of each pair: a periodic edge within two list cut-offs
  // of the largest pair lets a disc meet its own image (ignored, so its stress is lost) or a
  // pair meet twice (one contact history for two images).
  const double cutoff = 2.0 * amax * interaction_range_factor(cfg) + cfg.neighbour.skin;
  const bool periodic_y = scene_kind(cfg.scene.type).periodic_y;
  const double edge = periodic_y ? std::min(lx, ly) : lx;
  if (!(edge > 2.0 * cutoff))
    throw ConfigError(fmt::format(
        "{}: particles.N: the periodic cell is {:.3g} x {:.3g} d ({} = {:.3g} d), but a periodic "
        "edge must exceed twice the neighbour cut-off of the largest pair, 2 x {:.3g} = {:.3g} d "
        "(diameter {:g} d, lubrication range and neighbour.skin = {:g} d), or a disc meets its "
        "own image; raise particles.N{}, lower neighbour.skin or lubrication.h_max",
        origin, lx, ly, periodic_y && ly < lx ? "Ly" : "Lx", edge, cutoff, 2.0 * cutoff, 2.0 * amax,
        cfg.neighbour.skin,
        cfg.particles.init_file.empty() ? ", bring particles.aspect closer to 1" : ""));
}

Simulation::Simulation(const Config& cfg) : Simulation(cfg, build_scene(cfg)) {}

Simulation::Simulation(const Config& cfg, Scene scene)
    : cfg_(cfg), integrator_(make_integrator(cfg.integrator.type)) {
  StepLimits lim;
  lim.fixed_dt = cfg.integrator.dt;
  lim.max_displacement = cfg.integrator.max_displacement;
  lim.max_gap_fraction = cfg.integrator.max_gap_fraction;
  lim.max_overlap_change = overlap_change_limit(cfg);
  lim.max_strain_step = cfg.integrator.max_strain_step;
  lim.end_time = cfg.run.strain / cfg.flow.j;
  if (!integrator_->implicit_springs())
    lim.explicit_dt = cfg.integrator.explicit_safety * explicit_stability_dt(cfg);
  const double range = interaction_range_factor(cfg);
  ForceBalance fb(PairLaws::from(cfg), rotational_unknowns(cfg) ? 3 : 2,
                  integrator_->implicit_springs(), cfg.solver.cholesky);
  dynamics_ = std::make_unique<Dynamics>(std::move(scene.particles), scene.box, scene.flow,
                                         std::move(fb), NeighbourList(range, cfg.neighbour.skin),
                                         lim, std::move(scene.walls));
}

void Simulation::step() {
  if (!integrator_->step(*dynamics_))
    throw std::runtime_error(fmt::format(
        "linear solve failed at step {} (strain {:.6g}): the resistance matrix is not positive "
        "definite or the velocities are not finite",
        dynamics_->steps(), dynamics_->strain()));
}

// Only the observers the scene and the config ask for are composed into the run.
std::vector<std::unique_ptr<Observer>> make_observers(const Config& cfg,
                                                      const std::filesystem::path& out_dir) {
  std::vector<std::unique_ptr<Observer>> obs;
  obs.push_back(std::make_unique<RheologyObserver>(cfg.run.transient_strain));
  std::function<bool(const Dynamics&)> measuring;
  // A scene measured from its steady state has the pressure cell's detector of it.
  if (scene_kind(cfg.scene.type).measured_from_steady_state) {
    auto cell = std::make_unique<PressureCellObserver>(cfg);
    const PressureCellObserver* c = cell.get();
    measuring = [c](const Dynamics&) { return c->steady(); };
    obs.push_back(std::move(cell));
  } else {
    const double from = cfg.run.transient_strain;
    measuring = [from](const Dynamics& d) { return d.strain() > from; };
  }
  if (cfg.analysis.diffusion)
    obs.push_back(std::make_unique<DiffusionObserver>(cfg, out_dir / "analysis.h5", measuring));
  return obs;
}

namespace {

std::atomic<int> g_stop_signal{0};
extern "C" void on_stop_signal(int sig) {
  g_stop_signal.store(sig);
}

// Installs SIGINT/SIGTERM handlers for the lifetime of a run and restores the old ones.
struct StopSignals {
  struct sigaction old_int {
  }, old_term{};
  StopSignals() {
    g_stop_signal.store(0);
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
  }
  ~StopSignals() {
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
  }
};

// A reader's runtime_error on a checkpoint whose checksum held means another build's state
// layout; on an unchecked (version 2) one, corruption. Either way it is not resumed.
[[noreturn]] void unreadable_checkpoint(const std::filesystem::path& file, const char* what) {
  throw CorruptCheckpoint(fmt::format(
      "{} cannot be read: {}. It was neither resumed nor changed; keep a copy if you need it, "
      "then start the run again with --overwrite",
      file.string(), what));
}

// Whether DIR/config.toml holds this resolved configuration (compared through the parser, so
// that keys added to the code since do not make it look foreign).
bool same_config(const std::filesystem::path& file, const std::string& resolved) {
  try {
    return to_toml(load_config(file)) == resolved;
  } catch (const ConfigError&) {
    return false;
  }
}
// The same for the resolved text a checkpoint holds: an older sheardiff wrote it with other
// keys or other float digits (0.69999999999999996 for 0.7).
bool same_config_text(const std::string& text, const std::string& resolved) {
  if (text == resolved) return true;
  try {
    return to_toml(parse_config(text, "checkpoint.bin")) == resolved;
  } catch (const ConfigError&) {
    return false;
  }
}

std::string refusal(const RunDirectory& dir) {
  const std::string d = dir.path().string();
  switch (dir.state()) {
    case RunState::finished:
      return fmt::format(
          "{} holds a finished run (summary.json); it is left as it is. To run there again add "
          "--overwrite (this deletes its results), or choose another --out",
          d);
    case RunState::interrupted:
      return fmt::format(
          "{} holds an interrupted run (checkpoint.bin); it is left as it is. Continue it with "
          "`sheardiff run CONFIG --resume {}`, or add --overwrite to discard it",
          d, d);
    case RunState::started:
      return fmt::format(
          "{} holds a run that stopped before its first checkpoint ({}); it is left as it is. "
          "`sheardiff run CONFIG --resume {}` starts it again from strain 0, --overwrite "
          "replaces it",
          d, dir.run_files_present(), d);
    case RunState::empty:
      break;
  }
  return {};
}

}  // namespace

double next_output_strain(double next, double spacing, double strain) {
  const double until = strain * (1.0 + 1e-12);
  // A spacing far below one step (a Config made in code is not range checked): skip ahead
  // instead of adding it billions of times.
  if (next <= until && (until - next) / spacing > 1e6)
    next += std::floor((until - next) / spacing) * spacing;
  while (next <= until) {
    const double after = next + spacing;
    if (!(after > next)) return std::nextafter(until, std::numeric_limits<double>::infinity());
    next = after;
  }
  return next;
}

nlohmann::json run_to_directory(const Config& cfg, const std::filesystem::path& out_dir,
                                bool progress, bool resume) {
  RunDirectory dir(out_dir, !resume);
  return run_to_directory(cfg, dir, resume ? RunMode::resume : RunMode::start, progress);
}

// A function-try-block: every failure of the run passes the handlers at the end.
nlohmann::json run_to_directory(const Config& given, RunDirectory& dir, RunMode mode, bool progress,
                                double progress_seconds) try {
  // From here SIGINT/SIGTERM only set a flag: a signal during the set-up (minutes for a large
  // packing) stops the run at step 0 with a checkpoint instead of leaving a bare directory.
  StopSignals signals;
  // When the run started (a resumed run: its first start, kept in the checkpoint), as Unix
  // seconds; -1: unknown (a checkpoint of a sheardiff before the start was kept).
  std::int64_t started = std::chrono::duration_cast<std::chrono::seconds>(
                             std::chrono::system_clock::now().time_since_epoch())
                             .count();
  Config cfg = given;
  resolve_defaults(cfg);
  const std::string resolved = to_toml(cfg);
  const std::filesystem::path& out_dir = dir.path();
  const std::string out = out_dir.string();
  const auto checkpoint_file = dir.file("checkpoint.bin");

  // What is there decides what may be done; nothing is changed before the decision.
  const RunState state = dir.state();
  if (mode == RunMode::start && state != RunState::empty) throw ConfigError(refusal(dir));
  if (mode == RunMode::resume) {
    if (state == RunState::empty)
      throw ConfigError(fmt::format("--resume {}: there is no run there to resume", out));
    if (std::filesystem::exists(dir.file("config.toml")) &&
        !same_config(dir.file("config.toml"), resolved))
      throw ConfigError(fmt::format(
          "--resume {}: the configuration differs from the one the run was started with (see "
          "{}/config.toml)",
          out, out));
  }
  if (mode == RunMode::resume && state == RunState::finished) {
    // A run killed between its summary and the removal of its checkpoint is finished: say so,
    // and complete the removal.
    dir.start_log("resume of a finished run: " + this_command_line());
    std::error_code ec;
    std::filesystem::remove(checkpoint_file, ec);
    std::fprintf(stderr, "%s: the run has already finished (summary.json); nothing to resume\n",
                 out.c_str());
    std::ifstream in(dir.file("summary.json"));
    nlohmann::json js;
    try {
      js = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
      throw IoError(fmt::format("cannot read {}: {}", dir.file("summary.json").string(), e.what()));
    }
    return js;
  }
  const bool from_checkpoint = mode == RunMode::resume && state == RunState::interrupted;
  CheckpointPayload checkpoint;
  if (from_checkpoint) checkpoint = read_checkpoint_file(checkpoint_file);

  // The initial state is built before anything is written: a bad input file leaves no output.
  Simulation sim(cfg);
  Dynamics& d = sim.dynamics();
  const Particles& p = d.particles();
  // The residual is one sparse product per solve, small next to the factorisation.
  d.force_balance().set_check_residual(true);
  RunHealth health(cfg, d);
  auto observers = make_observers(cfg, out_dir);

  double next_frame = cfg.output.frame_strain;
  double next_checkpoint = cfg.output.checkpoint_strain;
  double elapsed_before = 0.0;
  long frames = 0;
  // The whole evolving state of the run, in one fixed order for saving and loading.
  // with_counters: version 3 checkpoints also hold the solver's work counters, and after them
  // the run's start time (absent from those of a sheardiff before it: then unknown).
  const auto serialize = [&](Archive& a, bool with_counters) {
    std::string config = resolved;
    a.io(config);
    if (!same_config_text(config, resolved))
      throw ConfigError(fmt::format(
          "--resume {}: the configuration differs from the one the checkpoint was written with "
          "(see {}/config.toml)",
          out_dir.string(), out_dir.string()));
    d.serialize(a);
    sim.serialize_integrator(a);
    for (auto& o : observers) o->serialize(a);
    health.serialize(a);
    a.io(next_frame), a.io(next_checkpoint), a.io(elapsed_before), a.io(frames);
    if (with_counters) {
      d.force_balance().system().serialize_counters(a);
      if (!a.loading() || !a.at_end())
        a.io(started);
      else
        started = -1;
    }
  };
  if (from_checkpoint) {
    Archive a = Archive::reader(std::move(checkpoint.bytes));
    try {
      serialize(a, checkpoint.checksummed);
    } catch (const ConfigError&) {
      throw;
    } catch (const std::exception& e) {
      unreadable_checkpoint(checkpoint_file, e.what());
    }
    if (!a.at_end()) unreadable_checkpoint(checkpoint_file, "bytes are left after the state");
  }

  // Only now is the directory changed: a new run starts from nothing of an earlier one.
  if (from_checkpoint)
    dir.remove_partial_files();
  else
    dir.remove_run_files(/*keep_log=*/mode == RunMode::resume);
  dir.start_log(this_command_line());
  if (from_checkpoint && !checkpoint.checksummed)
    std::fprintf(stderr,
                 "warning: %s has no checksum (written by an older sheardiff): resumed unchecked\n",
                 checkpoint_file.c_str());
  if (mode == RunMode::resume && !from_checkpoint)
    std::fprintf(stderr,
                 "%s: no checkpoint was written before the run stopped: starting again "
                 "from strain 0\n",
                 out.c_str());
  if (!from_checkpoint) write_file_atomically(dir.file("config.toml"), resolved);

  std::vector<std::string> names, units;
  for (const auto& o : observers) {
    for (auto& n : o->frame_names()) names.push_back(n);
    for (auto& u : o->frame_units()) units.push_back(u);
  }
  std::unique_ptr<H5mdWriter> writer;
  if (cfg.output.trajectory) {
    TrajectoryLayout layout;
    layout.n_particles = p.size();
    layout.species = p.species;
    for (double a : p.radius) layout.diameter.push_back(2.0 * a);
    for (Motion m : p.motion) layout.motion.push_back(static_cast<int>(m));
    layout.lx = d.box().lx;
    layout.ly = d.height();
    layout.lees_edwards = d.box().lees_edwards;
    layout.write_velocity = cfg.output.velocities;
    layout.observables = names;
    layout.observable_units = units;
    layout.write_contacts = cfg.output.contacts;
    layout.author = cfg.output.author;
    layout.creator_version = SHEARDIFF_VERSION;
    layout.config_toml = resolved;
    const auto file = dir.file("trajectory.h5");
    writer = from_checkpoint
                 ? std::make_unique<H5mdWriter>(H5mdWriter::resume(file, layout, frames))
                 : std::make_unique<H5mdWriter>(file, layout);
  }
  const auto save_checkpoint = [&](double elapsed_now) {
    if (writer) writer->flush();  // the trajectory holds every frame the checkpoint counts
    Archive a = Archive::writer();
    double total = elapsed_before + elapsed_now;
    std::swap(total, elapsed_before);
    serialize(a, true);
    std::swap(total, elapsed_before);
    // Whole or absent: a checkpoint is never half-written.
    const std::vector<char> bytes = checkpoint_file_bytes(a.bytes());
    write_file_atomically(checkpoint_file, bytes.data(), bytes.size());
  };

  // Progress: a live line redrawn on a terminal (not logged), and a timestamped line every
  // progress_seconds on stderr off a terminal, or in run.log alone (a terminal, --quiet).
  const bool tty = progress && dir.terminal();
  const auto t0 = std::chrono::steady_clock::now();
  const auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  auto last_print = t0, last_line = t0, last_flush = t0;
  bool shown = false;  // a live line is on the terminal: end it before anything else
  std::vector<double> values;
  const auto finished = [&] {
    for (const auto& o : observers)
      if (o->done(d)) return true;
    return d.strain() >= cfg.run.strain * (1.0 - 1e-12) ||
           (cfg.run.max_steps > 0 && d.steps() >= cfg.run.max_steps);
  };
  // A run gone wrong stops with a checkpoint if its state is finite (else the last one is
  // kept) and a diagnostic frame.
  const auto stop = [&](const HealthReport& r) {
    if (r.state_finite) save_checkpoint(seconds());
    write_diagnostic(dir.file("diagnostic.txt"), d, sim.integrator().velocities(), r);
    if (shown) std::fprintf(stderr, "\n");
    throw RunUnhealthy(r);
  };
  while (!finished()) {
    if (const int sig = g_stop_signal.load()) {
      save_checkpoint(seconds());
      if (shown) std::fprintf(stderr, "\n");
      throw RunInterrupted(
          sig,
          fmt::format(
              "stopped by signal {} at step {} (strain {:.6g}); checkpoint written: resume with "
              "`sheardiff run CONFIG --resume {}`",
              sig, d.steps(), d.strain(), out_dir.string()));
    }
    if (!sim.try_step()) stop(health.solver_failure(d, sim.integrator().velocities()));
    if (auto r = health.check(d, sim.integrator().velocities(), sim.integrator().last_dt()))
      stop(*r);
    const StressSample s = sim.sample();
    const StepView view{d, sim.integrator().velocities(), s, sim.integrator().last_dt()};
    for (const auto& o : observers) o->on_step(view);
    if (d.strain() >= next_frame * (1.0 - 1e-12)) {
      next_frame = next_output_strain(next_frame, cfg.output.frame_strain, d.strain());
      values.clear();
      for (const auto& o : observers) o->on_frame(view, values);
      if (writer) {
        FrameData f;
        f.step = d.steps();
        f.time = d.time();
        f.lx = d.box().lx;
        f.ly = d.height();
        f.tilt = d.box().le_offset;
        f.position = &p.position;
        f.unwrapped = &p.unwrapped;
        f.velocity = &sim.integrator().velocities().u;
        f.observables = values;
        ContactNetwork contacts;
        if (cfg.output.contacts) contacts = contact_network(d);
        f.contacts = &contacts;
        writer->write_frame(f);
      }
      ++frames;
      if (cfg.output.checkpoint_strain > 0.0 && d.strain() >= next_checkpoint * (1.0 - 1e-12)) {
        next_checkpoint =
            next_output_strain(next_checkpoint, cfg.output.checkpoint_strain, d.strain());
        save_checkpoint(seconds());
      }
    }
    const auto now = std::chrono::steady_clock::now();
    // The trajectory is flushed every half minute so that a killed run leaves readable frames.
    const bool live = tty && now - last_print > std::chrono::milliseconds(500);
    const bool line = std::chrono::duration<double>(now - last_line).count() > progress_seconds;
    if (live || line) {
      const double el = std::chrono::duration<double>(now - t0).count();
      // A pressure cell that has found its steady state stops at steady + measure_strain.
      double end = cfg.run.strain;
      for (const auto& o : observers) end = std::min(end, o->planned_end_strain());
      const double eta = el * std::max(end - d.strain(), 0.0) / std::max(d.strain(), 1e-12);
      const std::string text =
          fmt::format("strain {:.4g} / {:.4g}  steps {}  {:.0f} steps/s  ETA {}", d.strain(), end,
                      d.steps(), static_cast<double>(d.steps()) / el, duration_text(eta));
      if (live) {
        std::fprintf(stderr, "\r%s   ", text.c_str());
        last_print = now;
        shown = true;
      }
      if (line) {
        const std::string stamped = fmt::format("{}  {}\n", iso8601_utc_now(), text);
        if (progress && !tty)
          std::fputs(stamped.c_str(), stderr);
        else
          dir.log_only(stamped);
        last_line = now;
      }
    }
    if (writer && now - last_flush > std::chrono::seconds(30)) {
      writer->flush();
      last_flush = now;
    }
  }
  // The last move may have used up the skin: check it against a fresh neighbour list.
  if (d.neighbours().needs_rebuild()) {
    d.rebuild_now();
    if (auto r = health.check(d, sim.integrator().velocities(), sim.integrator().last_dt()))
      stop(*r);
  }
  if (shown) std::fprintf(stderr, "\n");
  const double wall = elapsed_before + seconds();

  // The end of the run. Every write below replaces what an earlier attempt may have written
  // (tables, analysis.h5, summary.json), so a death anywhere in it resumes from the last
  // checkpoint and completes; summary.json, written last, marks the run finished.
  nlohmann::json js;
  js["version"] = version();
  js["git_hash"] = git_hash();
  js["host"] = host_name();
  js["seed"] = cfg.run.seed;
  if (started >= 0)
    js["started"] =
        iso8601_utc(std::chrono::system_clock::time_point(std::chrono::seconds(started)));
  else
    js["started"] = nullptr;
  js["finished"] = iso8601_utc_now();
  js["scene"] = cfg.scene.type;
  js["N"] = cfg.particles.n;
  js["J"] = cfg.flow.j;
  js["ktilde"] = cfg.contact.ktilde;
  js["integrator"] = to_string(cfg.integrator.type);
  js["strain"] = d.strain();
  js["steps"] = d.steps();
  js["steps_per_strain"] = d.steps() / std::max(d.strain(), 1e-300);
  js["wall_seconds"] = wall;
  js["ms_per_step"] = 1e3 * wall / static_cast<double>(std::max<long>(d.steps(), 1));
  js["neighbour_rebuilds"] = d.neighbours().rebuilds();
  js["factorisations"] = d.force_balance().system().factorisations();
  {
    // Which limit set the steps: where the step count comes from.
    nlohmann::json by;
    const auto& counts = d.step_limit_counts();
    for (int k = 0; k < static_cast<int>(StepLimit::Count); ++k)
      if (counts[k] > 0)
        by[to_string(static_cast<StepLimit>(k))] =
            static_cast<double>(counts[k]) / static_cast<double>(std::max<long>(d.steps(), 1));
    js["dt_limited_by"] = by;
  }
  js["lx"] = d.box().lx;
  js["ly"] = d.height();
  dir.with_hdf5_reasons([&] {
    for (const auto& o : observers) o->finish(d, js, writer.get());
  });
  health.report(js);
  if (!js.contains("phi")) {
    double area = 0;
    for (std::size_t i = 0; i < p.n_mobile; ++i) area += kPi * p.radius[i] * p.radius[i];
    js["phi"] = area / (d.box().lx * d.height());
  }
  if (writer) writer->flush();
  writer.reset();
  // analysis.h5 is written by code that does not check its file's close: a full disk there
  // leaves a truncated file under the final name, which HDF5 then refuses to open.
  const auto analysis = dir.file("analysis.h5");
  if (cfg.analysis.diffusion && std::filesystem::exists(analysis) && !hdf5_file_opens(analysis)) {
    std::filesystem::remove(analysis);
    const std::string reason = dir.hdf5_log() ? dir.hdf5_log()->last_os_reason() : "";
    throw IoError(fmt::format("cannot write {}: {}", analysis.string(),
                              reason.empty() ? "the file was left incomplete" : reason));
  }
  write_file_atomically(dir.file("summary.json"), json_text(js) + "\n");
  // Finished: the summary marks the run complete and the checkpoint has served its purpose.
  std::filesystem::remove(checkpoint_file);
  return js;
} catch (const IoError& e) {
  // Once the run has taken charge of the directory (its log started), a failure leaves it
  // resumable: the last checkpoint whole (it is never half-written), no FILE.tmp, and the user
  // told how to go on.
  if (!dir.logging()) throw;
  dir.remove_partial_files();
  const std::string out = dir.path().string();
  throw IoError(fmt::format(
      "{}. {}", e.what(),
      dir.state() == RunState::interrupted
          ? fmt::format("{} is intact: once the cause is fixed, continue with `sheardiff run "
                        "CONFIG --resume {}`",
                        dir.file("checkpoint.bin").string(), out)
          : fmt::format("No checkpoint was written yet: once the cause is fixed, `sheardiff run "
                        "CONFIG --resume {}` starts the run again",
                        out)));
} catch (...) {
  if (dir.logging()) dir.remove_partial_files();
  throw;
}

}  // namespace sheardiff
