#include "sheardiff/run_parts.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <utility>

#include "sheardiff/core/text.hpp"
#include "sheardiff/integrator/stress.hpp"
#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/run_files.hpp"
#include "sheardiff/io/summary_keys.hpp"
#include "sheardiff/observe/channel.hpp"
#include "sheardiff/observe/diffusion_observer.hpp"
#include "sheardiff/observe/pressure_cell.hpp"
#include "sheardiff/observe/shear_analyses.hpp"
#include "sheardiff/run_extension.hpp"
#include "sheardiff/scene/registry.hpp"
#include "sheardiff/solver/blas_kernels.hpp"
#include "sheardiff/version.hpp"

namespace sheardiff {

namespace {

// A reader's runtime_error on a checkpoint whose checksum held means another build's state
// layout; on an unchecked (version 2) one, corruption. Either way it is not resumed.
[[noreturn]] void unreadable_checkpoint(const std::filesystem::path& file, const char* what) {
  throw CorruptCheckpoint(fmt::format(
      "{} cannot be read: {}. It was neither resumed nor changed; keep a copy if you need it, "
      "then start the run again with --overwrite",
      file.string(), what));
}

// Whether the resolved text a checkpoint holds is this configuration: an older sheardiff wrote
// it with other keys or other float digits (0.69999999999999996 for 0.7).
bool same_config_text(const std::string& text, const std::string& resolved) {
  if (text == resolved) return true;
  try {
    return to_toml(parse_config(text, "checkpoint.bin", {}, ConfigSource::record)) == resolved;
  } catch (const ConfigError&) {
    return false;
  }
}

}  // namespace

// ---- RunningState --------------------------------------------------------------------------

template <class D>
RunningStateOf<D>::RunningStateOf(const Config& cfg, const std::filesystem::path& out_dir,
                                  std::int64_t started_at)
    : sim(cfg),
      health(cfg, sim.dynamics()),
      observers(make_observers_of<D>(scene_kind(cfg.scene.type), cfg, out_dir)),
      next_frame(cfg.output.frame_strain),
      next_checkpoint(cfg.output.checkpoint_strain),
      started(started_at) {
  // The residual is one sparse product per solve, small next to the factorisation.
  sim.dynamics().force_balance().set_check_residual(true);
}

template <class D>
bool RunningStateOf<D>::finished(const Config& cfg) const {
  const auto& d = sim.dynamics();
  for (const auto& o : observers)
    if (o->done(d)) return true;
  return d.strain() >= cfg.run.strain * (1.0 - 1e-12) ||
         (cfg.run.max_steps > 0 && d.steps() >= cfg.run.max_steps);
}

template <class D>
double RunningStateOf<D>::planned_end_strain(const Config& cfg) const {
  // A pressure cell that has found its steady state stops at steady + measure_strain.
  double end = cfg.run.strain;
  for (const auto& o : observers) end = std::min(end, o->planned_end_strain());
  return end;
}

// ---- TrajectoryOutput ----------------------------------------------------------------------

namespace {

// The trajectory, opened (resume: cut back to the checkpoint's frames).
template <class D>
std::unique_ptr<H5mdWriter> open_trajectory(const Config& cfg, const RunningStateOf<D>& run,
                                            const RunDirectory& dir, const std::string& resolved,
                                            bool resume) {
  const auto& d = run.sim.dynamics();
  const auto& p = d.particles();
  TrajectoryLayout layout;
  for (const auto& o : run.observers) {
    for (auto& n : o->frame_names()) layout.observables.push_back(n);
    for (auto& u : o->frame_units()) layout.observable_units.push_back(u);
  }
  layout.n_particles = p.size();
  layout.species = p.species;
  for (double a : p.radius) layout.diameter.push_back(2.0 * a);
  for (Motion m : p.motion) layout.motion.push_back(static_cast<int>(m));
  layout.lx = d.box().lx;
  layout.ly = d.height();
  layout.dimension = D::space;
  layout.lees_edwards = d.box().lees_edwards;
  layout.write_velocity = cfg.output.velocities;
  layout.write_contacts = cfg.output.contacts;
  layout.author = cfg.output.author;
  layout.creator_version = SHEARDIFF_VERSION;
  layout.config_toml = resolved;
  const auto file = dir.file("trajectory.h5");
  return resume ? std::make_unique<H5mdWriter>(H5mdWriter::resume(file, layout, run.frames))
                : std::make_unique<H5mdWriter>(file, layout);
}

template <class D>
void write_trajectory_frame(H5mdWriter& writer, const Config& cfg, const RunningStateOf<D>& run,
                            const std::vector<double>& values) {
  const auto& d = run.sim.dynamics();
  const auto& p = d.particles();
  FrameData f;
  f.step = d.steps();
  f.time = d.time();
  f.lx = d.box().lx;
  f.ly = d.height();
  f.tilt = d.box().le_offset;
  f.observables = values;
  const bool images = p.image.size() == p.size();
  ContactNetwork contacts;
  if constexpr (D::space == 3) {
    f.lz = d.box().lz;
    f.position3 = &p.position;
    if (images) f.image3 = &p.image;
    // As for discs: under Lees-Edwards the unwrapped x is not position + image . edges.
    if (d.box().lees_edwards && images) f.unwrapped3 = &p.unwrapped;
    f.velocity6 = &run.sim.integrator().velocities().u;
    if (cfg.output.contacts) contacts = contact_network(d);
    f.contacts = &contacts;
  } else {
    f.position = &p.position;
    // Without Lees-Edwards the unwrapped position is position + image . edges: not stored twice.
    if (d.box().lees_edwards) f.unwrapped = &p.unwrapped;
    if (images) f.image = &p.image;
    f.velocity = &run.sim.integrator().velocities().u;
    if (cfg.output.contacts) contacts = contact_network(d);
    f.contacts = &contacts;
  }
  writer.write_frame(f);
}

}  // namespace

template <class D>
TrajectoryOutputOf<D>::TrajectoryOutputOf(const Config& cfg, const RunningStateOf<D>& run,
                                          const RunDirectory& dir, const std::string& resolved,
                                          bool resume) {
  if (cfg.output.trajectory) writer_ = open_trajectory(cfg, run, dir, resolved, resume);
}

template <class D>
void TrajectoryOutputOf<D>::write_frame(const Config& cfg, const RunningStateOf<D>& run,
                                        const std::vector<double>& values) {
  if (writer_) write_trajectory_frame(*writer_, cfg, run, values);
}

template <class D>
void TrajectoryOutputOf<D>::flush_now_and_then() {
  if (!writer_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_flush_ > std::chrono::seconds(2)) {
    writer_->flush();
    last_flush_ = now;
  }
}

template <class D>
void TrajectoryOutputOf<D>::close() {
  flush();
  writer_.reset();
}

// ---- CheckpointStore -----------------------------------------------------------------------

// The whole evolving state of the run, in one fixed order for saving and loading.
// with_counters: version 3 checkpoints also hold the solver's work counters, and after them
// the run's start time (absent from those of a sheardiff before it: then unknown).
template <class D>
void CheckpointStoreOf<D>::serialize(Archive& a, RunningStateOf<D>& run, int layout) const {
  const bool with_counters = layout >= 3;
  std::string config = resolved_;
  a.io(config);
  // An extended run's checkpoint was written with the run's earlier end.
  if (!same_config_text(config, resolved_) && !only_moves_the_end(config, resolved_))
    throw ConfigError(fmt::format(
        "--resume {}: the configuration differs from the one the checkpoint was written with "
        "(see {}/config.toml)",
        out_, out_));
  auto& d = run.dynamics();
  d.serialize(a, layout >= 5);
  run.sim.serialize_integrator(a);
  for (auto& o : run.observers) o->serialize(a);
  run.health.serialize(a);
  a.io(run.next_frame), a.io(run.next_checkpoint), a.io(run.elapsed_before), a.io(run.frames);
  if (with_counters) {
    d.force_balance().system().serialize_counters(a);
    if (!a.loading() || !a.at_end())
      a.io(run.started);
    else
      run.started = -1;
    if (!a.loading() || !a.at_end()) d.force_balance().serialize_sticking_counts(a);
  }
}

template <class D>
void CheckpointStoreOf<D>::load(RunningStateOf<D>& run, CheckpointPayload payload) const {
  // Layout 4 moved the gap profiles out of the pressure cell's section (ProfilesObserver): an
  // older pressure-cell state cannot be placed, and reading it would fail half-way as "corrupt".
  if (payload.layout < 4)
    for (const auto& o : run.observers)
      if (dynamic_cast<const PressureCellObserverOf<D>*>(o.get()) != nullptr)
        throw CorruptCheckpoint(fmt::format(
            "{} was written by an earlier sheardiff (checkpoint layout {}), whose pressure-cell "
            "state this version stores differently. It was neither resumed nor changed: finish "
            "the run with the sheardiff that started it (its version and git hash are at the top "
            "of {}/run.log), or start it again with --overwrite",
            file_.string(), payload.layout, out_));
  // Layout 6 accumulates the diffusion analysis instead of keeping the window's frames.
  if (payload.layout < 6)
    for (const auto& o : run.observers)
      if (dynamic_cast<const DiffusionObserverOf<D>*>(o.get()) != nullptr)
        throw CorruptCheckpoint(fmt::format(
            "{} was written by an earlier sheardiff (checkpoint layout {}), which kept the "
            "measured window's frames for the diffusion analysis; this version accumulates it "
            "while running. It was neither resumed nor changed: finish the run with the "
            "sheardiff that started it (its version and git hash are at the top of "
            "{}/run.log), or start it again with --overwrite",
            file_.string(), payload.layout, out_));
  Archive a = Archive::reader(std::move(payload.bytes), payload.layout);
  try {
    serialize(a, run, payload.layout);
  } catch (const ConfigError&) {
    throw;
  } catch (const std::exception& e) {
    unreadable_checkpoint(file_, e.what());
  }
  if (!a.at_end()) unreadable_checkpoint(file_, "bytes are left after the state");
}

template <class D>
void CheckpointStoreOf<D>::save(RunningStateOf<D>& run, double elapsed_now,
                                TrajectoryOutputOf<D>& trajectory,
                                const std::filesystem::path& to) const {
  trajectory.flush();  // the trajectory holds every frame the checkpoint counts
  Archive a = Archive::writer();
  double total = run.elapsed_before + elapsed_now;
  std::swap(total, run.elapsed_before);
  serialize(a, run, CheckpointPayload{}.layout);
  std::swap(total, run.elapsed_before);
  // Whole or absent: a checkpoint is never half-written.
  const std::vector<char> bytes = checkpoint_file_bytes(a.bytes());
  write_file_atomically(to.empty() ? file_ : to, bytes.data(), bytes.size());
}

// ---- RunProgress ---------------------------------------------------------------------------

RunProgress::RunProgress(RunDirectory& dir, bool progress, double seconds, double strain,
                         long steps)
    : dir_(dir),
      progress_(progress),
      tty_(progress && dir.terminal()),
      seconds_(seconds),
      t0_(std::chrono::steady_clock::now()),
      last_print_(t0_),
      last_line_(t0_),
      strain0_(strain),
      steps0_(steps) {}

double RunProgress::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
}

void RunProgress::update(double strain, long steps, double end, const std::string& more) {
  const auto now = std::chrono::steady_clock::now();
  const bool live = tty_ && now - last_print_ > std::chrono::milliseconds(500);
  const bool line = std::chrono::duration<double>(now - last_line_).count() > seconds_;
  if (!live && !line) return;
  const double el = std::chrono::duration<double>(now - t0_).count();
  const double eta = el * std::max(end - strain, 0.0) / std::max(strain - strain0_, 1e-12);
  std::string text =
      fmt::format("strain {:.4g} / {:.4g}  steps {}  {:.0f} steps/s  ETA {}{}", strain, end, steps,
                  static_cast<double>(steps - steps0_) / el, duration_text(eta), more);
  if (live) {
    std::fprintf(stderr, "\r%s   ", text.c_str());
    last_print_ = now;
    shown_ = true;
  }
  if (line) {
    const std::string stamped = fmt::format("{}  {}\n", iso8601_utc_now(), text);
    if (progress_ && !tty_)
      std::fputs(stamped.c_str(), stderr);
    else
      dir_.log_only(stamped);
    last_line_ = now;
  }
}

void RunProgress::end_line() {
  if (shown_) std::fprintf(stderr, "\n");
  shown_ = false;
}

// ---- The summary ---------------------------------------------------------------------------

template <class D>
nlohmann::json run_summary(const Config& cfg, RunningStateOf<D>& run, double wall_seconds,
                           RunDirectory& dir, TrajectoryOutputOf<D>& trajectory) {
  const auto& d = run.sim.dynamics();
  const auto& p = d.particles();
  nlohmann::json js;
  js[summary_key::version] = version();
  js[summary_key::git_hash] = git_hash();
  js[summary_key::host] = host_name();
  if (const auto kernels = openblas_kernels())
    js[summary_key::blas_kernels] = *kernels;
  else
    js[summary_key::blas_kernels] = nullptr;
  js[summary_key::seed] = cfg.run.seed;
  if (run.started >= 0)
    js[summary_key::started] =
        iso8601_utc(std::chrono::system_clock::time_point(std::chrono::seconds(run.started)));
  else
    js[summary_key::started] = nullptr;
  js[summary_key::finished] = iso8601_utc_now();
  js[summary_key::scene] = cfg.scene.type;
  js[summary_key::dimension] = D::space;
  js[summary_key::N] = static_cast<std::int64_t>(p.n_mobile);
  if (scene_kind(cfg.scene.type).imposes_shear_rate()) js[summary_key::J] = cfg.flow.j;
  js[summary_key::ktilde] = cfg.contact.ktilde;
  js[summary_key::integrator] = to_string(cfg.integrator.type);
  js[summary_key::strain] = d.strain();
  js[summary_key::steps] = d.steps();
  js[summary_key::steps_per_strain] = d.steps() / std::max(d.strain(), 1e-300);
  js[summary_key::wall_seconds] = wall_seconds;
  js[summary_key::ms_per_step] =
      1e3 * wall_seconds / static_cast<double>(std::max<long>(d.steps(), 1));
  js[summary_key::neighbour_rebuilds] = d.neighbours().rebuilds();
  js[summary_key::factorisations] = d.force_balance().system().factorisations();
  {
    // Where factorisations beyond one per step come from (implicit springs at low J).
    const auto& sc = d.force_balance().sticking_counts();
    const double steps = static_cast<double>(std::max<long>(d.steps(), 1));
    js[summary_key::sticking_resolves_per_step] = {
        {"low_rank", static_cast<double>(sc.low_rank) / steps},
        {"refactorised_budget", static_cast<double>(sc.refactorised_budget) / steps},
        {"switched_contacts", static_cast<double>(sc.switched) / steps}};
  }
  {
    // Which limit set the steps: where the step count comes from.
    nlohmann::json by;
    const auto& counts = d.step_limit_counts();
    for (int k = 0; k < static_cast<int>(StepLimit::Count); ++k)
      if (counts[k] > 0)
        by[to_string(static_cast<StepLimit>(k))] =
            static_cast<double>(counts[k]) / static_cast<double>(std::max<long>(d.steps(), 1));
    js[summary_key::dt_limited_by] = by;
  }
  js[summary_key::lx] = d.box().lx;
  js[summary_key::ly] = d.height();
  dir.with_hdf5_reasons([&] {
    for (const auto& o : run.observers) o->finish(d, js, trajectory.writer());
  });
  run.health.report(js);
  if (!js.contains(summary_key::phi)) {
    double taken = 0;
    for (std::size_t i = 0; i < p.n_mobile; ++i) taken += particle_measure<D>(p.radius[i]);
    js[summary_key::phi] = taken / (band_section(d) * d.height());
  }
  return js;
}

// Only the observers the scene and the config ask for are composed into the run.
ObserverList make_observers(const Config& cfg, const std::filesystem::path& out_dir) {
  return make_observers(scene_kind(cfg.scene.type), cfg, out_dir);
}

template <class D>
ObserverListOf<D> make_observers_of(const SceneKind& scene, const Config& cfg,
                                    const std::filesystem::path& out_dir) {
  ObserverListOf<D> obs;
  obs.push_back(std::make_unique<RheologyObserverOf<D>>(cfg.run.transient_strain));
  switch (scene.measures) {
    case Measures::ShearAfterTransient: {
      const double from = cfg.run.transient_strain;
      add_shear_analyses<D>(
          obs, cfg, out_dir, [from](const DynamicsOf<D>& d) { return d.strain() > from; },
          !scene.periodic_y);
      break;
    }
    case Measures::ShearFromSteadyState: {
      auto cell = std::make_unique<PressureCellObserverOf<D>>(cfg);
      const PressureCellObserverOf<D>* c = cell.get();
      obs.push_back(std::move(cell));
      add_shear_analyses<D>(
          obs, cfg, out_dir, [c](const DynamicsOf<D>&) { return c->steady(); }, !scene.periodic_y);
      break;
    }
    case Measures::ChannelMigration:
      // The channel is a scene of discs (the configuration check refuses it with spheres).
      if constexpr (D::space == 2)
        obs.push_back(std::make_unique<ChannelObserver>(cfg, out_dir / kChannelFile));
      break;
  }
  return obs;
}

template struct RunningStateOf<Dim2>;
template struct RunningStateOf<Dim3>;
template class TrajectoryOutputOf<Dim2>;
template class TrajectoryOutputOf<Dim3>;
template class CheckpointStoreOf<Dim2>;
template class CheckpointStoreOf<Dim3>;
template nlohmann::json run_summary(const Config&, RunningStateOf<Dim2>&, double, RunDirectory&,
                                    TrajectoryOutputOf<Dim2>&);
template nlohmann::json run_summary(const Config&, RunningStateOf<Dim3>&, double, RunDirectory&,
                                    TrajectoryOutputOf<Dim3>&);
template ObserverListOf<Dim2> make_observers_of(const SceneKind&, const Config&,
                                                const std::filesystem::path&);
template ObserverListOf<Dim3> make_observers_of(const SceneKind&, const Config&,
                                                const std::filesystem::path&);

}  // namespace sheardiff
