// The units and meanings of the summary.json keys (include/sheardiff/io/summary_keys.hpp): the
// source of docs/outputs.md's key tables (`sheardiff summary-keys --markdown`).
#include "sheardiff/io/summary_keys.hpp"

#include <fmt/format.h>

#include <sstream>

namespace sheardiff {

namespace sk = summary_key;

std::vector<SummaryKeyGroup> summary_key_groups() {
  return {
      {"Every run: identity, cost and health",
       "",
       {
           {sk::version, "-", "sheardiff version string (e.g. \"0.1.0\")"},
           {sk::git_hash, "-",
            "short git commit of the build; \"-dirty\" if tracked files had changes, \"unknown\" "
            "outside a checkout"},
           {sk::host, "-", "host name of the machine that finished the run"},
           {sk::blas_kernels, "-",
            "OpenBLAS's kernel set on that machine (\"Cooperlake\", \"Haswell\"; "
            "docs/performance.md \"The BLAS kernels\"); null when the BLAS is not OpenBLAS"},
           {sk::seed, "-", "`run.seed`: seeds the packing and the MSD reference times"},
           {sk::started, "ISO 8601 UTC",
            "when the run first started (kept across resumes); null when a checkpoint of an older "
            "version did not record it"},
           {sk::finished, "ISO 8601 UTC", "when the summary was written"},
           {sk::scene, "-", "`scene.type`: \"simple_shear\", \"pressure_shear\" or \"channel\""},
           {sk::dimension, "-",
            "`scene.dimension`: 2 (discs in a monolayer) or 3 (spheres); phi is then an area or "
            "a volume fraction"},
           {sk::N, "count", "number of mobile particles (wall particles excluded)"},
           {sk::J, "1",
            "viscous number `flow.J` = eta gammadot / P, which is the shear rate in these units "
            "(not written for the channel)"},
           {sk::ktilde, "1", "contact stiffness kn / (P d) (`contact.ktilde`)"},
           {sk::integrator, "-", "`integrator.type`: \"euler\", \"heun\" or \"implicit\""},
           {sk::strain, "strain",
            "the run's clock at its end: gammadot t; in a channel the time in a/<u>"},
           {sk::steps, "count", "time steps taken"},
           {sk::steps_per_strain, "1/strain", "steps / strain (per a/<u> in a channel)"},
           {sk::wall_seconds, "s",
            "wall-clock time of the run, summed over its start and its resumes (each part up to "
            "its last checkpoint or the end)"},
           {sk::ms_per_step, "ms", "1000 wall_seconds / steps"},
           {sk::neighbour_rebuilds, "count", "rebuilds of the Verlet neighbour list"},
           {sk::factorisations, "count",
            "numeric Cholesky factorisations of the resistance matrix (more than one per step when "
            "steps are redone or sticking re-solves refactorise)"},
           {sk::sticking_resolves_per_step, "per step",
            "object, the cost of the implicit integrator's sticking re-solves per step: `low_rank` "
            "(passes solved on the old factor with low-rank updates), `refactorised_budget` "
            "(passes refactorised because the update would cost more), `switched_contacts` "
            "(contacts switched from sliding to sticking)"},
           {sk::dt_limited_by, "fraction of steps",
            "object: for each step limit that ever set dt, the share of steps it set: `fixed` "
            "(fixed `integrator.dt`), `strain` (`max_strain_step`), `displacement`, `gap`, "
            "`overlap`, `explicit_stability`, `growth` (the x1.25 growth cap), docs/numerics.md"},
           {sk::lx, "d", "periodic length of the cell in x"},
           {sk::ly, "d",
            "height at the end: Ly of the periodic cell (simple shear), else the distance between "
            "the walls' mean centre lines (pressure cell: the final H; channel: H + d)"},
           {sk::health, "-",
            "object of the run health checks (docs/stability.md): `max_overlap` (largest overlap "
            "of any pair at any step, d), `max_residual` (largest relative residual \\|A U - F\\| "
            "/ \\|F\\| of a solve, 1), `max_overlap_limit` and `max_residual_limit` "
            "(`health.max_overlap`, `health.max_residual`)"},
           {sk::analysed_by, "-",
            "version line (\"sheardiff VERSION (git HASH)\") of the `sheardiff analyse` that added "
            "to or recomputed this summary; absent in a run's own summary"},
           {sk::analysed_with, "-",
            "array of the `sheardiff analyse --set` overrides (analysis.* and observables.* keys) "
            "this summary in reanalysis/ was computed with; absent otherwise"},
       }},
      {"The rheology",
       "Averages over the steps (weighted by dt) after `run.transient_strain`, from the pair "
       "forces (lubrication, contacts, repulsion; the one-body drag is left out), divided by the "
       "cell's area times l_z (docs/model.md section 9). In the pressure cell they are not "
       "limited to the steady window: they start at `averaged_from_strain` (0 by default).",
       {
           {sk::averaged_from_strain, "strain",
            "`run.transient_strain`: the strain after which the keys of this table are averaged"},
           {sk::shear_stress, "P",
            "sigma_xy of the pair forces, positive when the suspension resists the shear; null if "
            "the run ended before averaged_from_strain"},
           {sk::pressure, "P",
            "particle pressure -(sigma_xx + sigma_yy) / 2 of the pair forces (spheres: the trace "
            "over 3); "
            "null as above"},
           {sk::viscosity, "eta",
            "shear_stress / gammadot with gammadot = J; in a channel gammadot is the Poiseuille "
            "wall shear rate 6 <u> / H, so this number has no rheological meaning there; null as "
            "above"},
           {sk::contacts_per_particle, "1",
            "mean number of pairs in contact (wall contacts included) per mobile disc, about half "
            "the coordination number; null as above"},
           {sk::mean_overlap, "d",
            "time average of the mean overlap of the contacts; null as above"},
           {sk::max_overlap, "d",
            "largest contact overlap at any step of the run, transient included"},
           {sk::phi, "1",
            "area fraction. Simple shear: mobile disc area / (Lx Ly). Pressure cell: bulk phi, the "
            "disc area in the slab `observables.wall_exclusion` inside the wall lines over the "
            "slab's area, time-averaged over the measured window (if not steady: of the last "
            "configuration). Channel: mobile disc area / (Lx (H + d)), over the wall rows' centre "
            "lines, not channel.phi. Spheres: volume fraction, sphere volumes (cut exactly by the "
            "slab's planes) over Lx Lz times the slab's height"},
       }},
      {"The pressure cell: steady state and window means",
       "The steady-state detector and the measured window are described in docs/model.md "
       "(\"Steady state\") and docs/numerics.md. The means are over the steps (weighted by dt) "
       "from `steady_detected_at` to the end of the run. Their errors are batch means over time "
       "blocks of the frames of that window: the standard error of the window mean.",
       {
           {sk::steady, "bool",
            "whether steady state was detected and something measured after it"},
           {sk::steady_strain, "strain",
            "start of the detector's window at detection (steady_detected_at - `steady.window`); "
            "null if never steady"},
           {sk::steady_detected_at, "strain",
            "strain of the frame at which steady state was detected: the measured window starts "
            "here; null if never steady"},
           {sk::measured_strain, "strain",
            "length of the measured window, strain at the end - steady_detected_at"},
           {sk::note, "-",
            "only when `steady` is false: why (not reached, or detected at the last step); the "
            "means below are then absent and H and phi are of the last configuration"},
           {sk::H, "d",
            "gap between the walls' mean centre lines, time-averaged over the measured window"},
           {sk::H_err, "d",
            "standard error of H: batch means over time blocks; null if not finite"},
           {sk::phi_err, "1", "standard error of the bulk phi (batch means)"},
           {sk::phi_std, "1",
            "standard deviation in time of the bulk phi over the measured window (a fluctuation, "
            "not an error)"},
           {sk::mu, "1", "friction coefficient (mu_top + mu_bottom) / 2"},
           {sk::mu_err, "1",
            "standard error of mu (batch means of the per-frame (mu_top + mu_bottom) / 2)"},
           {sk::mu_top, "1",
            "-F_top,x / (P Lx l_z), spheres P Lx Lz: shear force of the suspension on the top "
            "wall over its load"},
           {sk::mu_top_err, "1", "standard error of mu_top (batch means)"},
           {sk::mu_bottom, "1",
            "+F_bottom,x / (P Lx l_z), spheres P Lx Lz: the same on the bottom wall"},
           {sk::mu_bottom_err, "1", "standard error of mu_bottom (batch means)"},
           {sk::steady_errors_note, "-",
            "present instead of the five `*_err` keys above when the window has fewer than 8 "
            "frames: says so and how to get error bars"},
           {sk::pressure_measured, "P",
            "time mean of F_top,y / (Lx l_z), the packing's normal force on the top wall; equals P "
            "= 1 to round-off by construction"},
           {sk::pressure_max_relative_error, "1",
            "largest \\|F_top,y / (Lx l_z) - P\\| / P over all steps of the run, free-fall steps "
            "excluded"},
           {sk::wall_free_fall_steps, "count",
            "steps in which nothing held the top wall and its speed was capped at "
            "`walls.free_fall_speed`"},
       }},
      {"The pressure cell: stationarity of the measured window",
       "Four signals recorded at every frame, judged at the end (docs/model.md, \"Steady "
       "state\"). These keys are written only for a steady run, and the signals only when its "
       "window has at least 8 frames. Their errors are batch means over time blocks.",
       {
           {sk::stationary, "bool",
            "true when all four signals pass; false for a window of fewer than 8 frames"},
           {sk::not_stationary, "-",
            "the failed signals, comma separated; \"\" when stationary, \"window too short\" with "
            "fewer than 8 frames"},
           {sk::stationarity_warning, "-",
            "present when not stationary: the window's averages describe a transient"},
           {sk::net_drag_y, "P",
            "window mean of (F_top,y + F_bottom,y) / (Lx l_z), the fluid's net y drag on the discs "
            "(positive when they sink); passes when 0 within `steady.drift_z` errors"},
           {sk::net_drag_y_err, "P", "standard error of that mean (batch means)"},
           {sk::mu_top_minus_bottom, "1",
            "window mean of mu_top - mu_bottom, the net x drag on the discs; passes when 0 within "
            "`steady.drift_z` errors"},
           {sk::mu_top_minus_bottom_err, "1", "standard error of that mean (batch means)"},
           {sk::H_change, "d",
            "change of H across the window: slope of the least-squares line through the block "
            "means of H times the window length; passes when 0 within `steady.drift_z` errors"},
           {sk::H_change_err, "d",
            "standard error of that change, from the block means' scatter about the line"},
           {sk::bulk_normal_load, "P",
            "window mean of the normal load carried by the bulk band (-sigma_yy of the pair forces "
            "with midpoints in it); passes within `steady.bulk_load_tolerance` of 1"},
           {sk::bulk_normal_load_err, "P",
            "standard error of that mean (batch means; reported, not used in the verdict)"},
           {sk::window_blocks, "-",
            "object of arrays, one entry per time block of the window (the blocks of the errors "
            "and of H_change): `strain` (block midpoints), and the block means of `H` (d), `phi`, "
            "`mu`, `mu_top_minus_bottom`, `net_drag_y` (P) and `bulk_normal_load` (P); a signal "
            "the run did not record, or with an empty block, is null"},
       }},
      {"The pressure cell: profiles across the gap",
       "Time averages over the measured window, weighted by dt, in bins of "
       "`observables.profile_bin` from the bottom wall's centre line (`observables.profiles = "
       "true`; `src/observe/profiles.cpp`). Each is an array with one entry per bin; the bins "
       "cover at least H + 2 d, so the last ones can be empty (0).",
       {
           {sk::profile_bin, "d", "bin width"},
           {sk::profile_y, "d", "array: bin centres above the bottom wall's centre line"},
           {sk::profile_phi, "1",
            "array: area fraction, each disc's exact area in each bin over the bin's area "
            "(spheres: volume fraction, each sphere's exact volume in the bin over Lx Lz bin)"},
           {sk::profile_u_x, "gammadot d",
            "array: mean x velocity of the discs whose centres are in the bin, over gammadot"},
           {sk::profile_T, "(gammadot d)^2",
            "array: <u_x^2> - <u_x>^2 + <u_y^2> of those discs, over gammadot^2 (spheres: the "
            "same x-y part; u_z is not counted)"},
           {sk::profile_shear_stress, "P",
            "array: sigma_xy of the pair forces, each pair in the bin of its midpoint, over the "
            "bin's volume Lx bin l_z"},
           {sk::profile_pressure, "P",
            "array: -(sigma_xx + sigma_yy) / 2 of the pair forces (spheres: the trace over 3), "
            "binned "
            "the same way"},
           {sk::profile_shear_stress_lubrication, "P",
            "array: the part of profile_shear_stress the lubrication forces make (squeeze, shear "
            "and pump, at contact the dashpots); the rest is the contacts' springs and, where it "
            "is on, the repulsion. Written with lubrication on, unless the run was resumed "
            "mid-window from a checkpoint of an earlier sheardiff (layout 8 or before)"},
           {sk::profile_pressure_lubrication, "P",
            "array: the part of profile_pressure the lubrication forces make, written as "
            "profile_shear_stress_lubrication is"},
           {sk::bulk_shear_rate_ratio, "1",
            "slope of a least-squares line through u_x(y) over the bins at least "
            "`observables.wall_exclusion` from both walls, over the imposed gammadot (1 for a "
            "linear profile); written with 3 or more such bins"},
           {sk::profiles_from, "-",
            "\"frames\": only in a summary completed by `sheardiff analyse` for a run without "
            "profiles, computed from the trajectory's frames (without the stress profiles)"},
       }},
      {"The diffusion analysis",
       "Self-diffusion in the gradient direction y over the measured window: after "
       "`run.transient_strain` in simple shear, from `steady_detected_at` in the pressure cell "
       "(docs/numerics.md, \"Diffusion analysis\"; `src/analysis/diffusion.cpp`). Psi denotes the "
       "persistence time of the velocity autocorrelation C(tau) = <v_y(t0) v_y(t0 + tau)>. The "
       "errors of dv and every Psi are delete-one-block jackknife errors over time blocks. The "
       "`*_bulk` keys count a disc at a reference time only if its centre is "
       "`observables.wall_exclusion` inside both walls' centre lines (pressure cell only).",
       {
           {sk::D, "gammadot d^2",
            "self-diffusion coefficient: half the slope of a least-squares line through the MSD "
            "over the fit window, the MSD over every origin of the samples "
            "`analysis_coarse_strain` apart (`/msd_coarse`)"},
           {sk::D_err, "gammadot d^2",
            "standard error of D from time blocks: the exact block decomposition of the MSD-slope "
            "estimator's variance (Rademacher wild bootstrap between blocks, covariance across "
            "blocks within one); null if it could not be formed"},
           {sk::D_regression_stderr, "gammadot d^2",
            "the line fit's own standard error of D; treats the correlated MSD points as "
            "independent and badly underestimates the error (kept for comparison)"},
           {sk::D_all_reference_times, "gammadot d^2",
            "D from the estimator that D_err is the error of: the same fit over the whole error "
            "blocks only (the samples past the last whole block left out); null if not computable"},
           {sk::D_x, "gammadot d^2",
            "half the slope of the MSD of the x displacement relative to the imposed flow over the "
            "fit window (the run only; not diffusive in general: shear disperses it, see "
            "`msd_x_window_slope`)"},
           {sk::msd_x_window_slope, "1", "log-log slope of that MSD over the fit window"},
           {sk::velocity_intervals, "strain",
            "array: the intervals Delta of `analysis.velocity_intervals`, rounded to the "
            "analysis's grid (k 2^l samples, k <= 15); only when that list is not empty"},
           {sk::dv_intervals, "gammadot d",
            "array: dv of the displacement velocity (y(t) - y(t - Delta)) / Delta, one per "
            "interval"},
           {sk::dv_intervals_err, "gammadot d", "array: their jackknife errors"},
           {sk::psi_intervals, "1/gammadot",
            "array: Psi (integral to the first zero) of that velocity's autocorrelation, one per "
            "interval"},
           {sk::psi_intervals_err, "1/gammadot", "array: their jackknife errors"},
           {sk::D_bulk, "gammadot d^2", "D of the bulk-only MSD (no error bar)"},
           {sk::dv, "gammadot d",
            "velocity fluctuation <v_y^2>^(1/2) = C(0)^(1/2) over every mobile disc and frame"},
           {sk::dv_err, "gammadot d", "jackknife error of dv"},
           {sk::dv_bulk, "gammadot d", "dv over bulk origins"},
           {sk::dv_bulk_err, "gammadot d", "jackknife error of dv_bulk"},
           {sk::psi, "1/gammadot",
            "persistence time: integral of C / C(0) up to its first zero crossing (interpolated), "
            "or up to `analysis.vacf_max_lag` if C never crosses zero"},
           {sk::psi_err, "1/gammadot", "jackknife error of psi"},
           {sk::psi_e, "1/gammadot",
            "first lag at which C / C(0) falls to 1/e; null if it never does"},
           {sk::psi_e_err, "1/gammadot", "jackknife error of psi_e"},
           {sk::psi_zero, "1/gammadot", "first zero crossing of C; null if C stays positive"},
           {sk::psi_zero_err, "1/gammadot", "jackknife error of psi_zero"},
           {sk::psi_full, "1/gammadot",
            "integral of C / C(0) over every lag up to `analysis.vacf_max_lag` (the Green-Kubo "
            "value, D / dv^2 once the lags reach the diffusive regime)"},
           {sk::psi_full_err, "1/gammadot", "jackknife error of psi_full"},
           {sk::psi_bulk, "1/gammadot", "psi over bulk origins"},
           {sk::psi_bulk_err, "1/gammadot", "jackknife error of psi_bulk"},
           {sk::psi_e_bulk, "1/gammadot", "psi_e over bulk origins"},
           {sk::psi_full_bulk, "1/gammadot", "psi_full over bulk origins"},
           {sk::psi_from_D, "1/gammadot",
            "D / dv^2: the persistence time a random walk with this D and dv would have; null if "
            "dv = 0"},
           {sk::step_length, "d", "dv psi"},
           {sk::diffusion_consistency, "1",
            "D / (dv^2 psi): 1 when the VACF integral up to its zero crossing carries the whole "
            "diffusion"},
           {sk::msd_window, "strain",
            "array [lo, hi]: the MSD fit window actually used; shorter than [`msd_window_lo`, "
            "`msd_window_hi`] (with a warning) when the measured window is"},
           {sk::msd_window_slope, "1",
            "slope of log MSD against log lag over the fit window: 1 if diffusive, 2 if ballistic; "
            "null with fewer than 3 points"},
           {sk::error_block_strain, "strain",
            "length of the error blocks used: `analysis.error_block`, shortened so that at least 4 "
            "blocks fit in the window"},
           {sk::error_blocks, "count", "number of time blocks of the jackknife"},
           {sk::bulk_fraction, "1", "share of the (disc, frame) samples that are in the bulk"},
           {sk::analysis_samples, "count",
            "samples in the measured window that were analysed (frames, for `sheardiff analyse`)"},
           {sk::analysis_sample_strain, "strain",
            "their spacing: `analysis.sample_strain` in the run, `output.frame_strain` in analyse"},
           {sk::analysis_coarse_strain, "strain",
            "spacing of the samples D is fitted to: `analysis.coarse_strain` rounded to whole "
            "samples"},
           {sk::analysis_warnings, "-",
            "array of strings: a fit window cut short, a non-diffusive MSD, C(tau) resolved by "
            "fewer than 10 samples per psi, sample marks skipped by steps longer than "
            "`analysis.sample_strain`, error blocks shorter than 10 psi, no error bar for D, no "
            "disc in the bulk; or, alone, \"no diffusion analysis: ...\" when the window is too "
            "short"},
       }},
      {"The channel",
       "Written by the channel scene (`src/observe/channel.cpp`, docs/channel.md, "
       "\"Outputs\"). Profiles are arrays over bins of about a/2 across the width H (entries null "
       "where a bin held no disc). They and the table values are averages from "
       "`channel_average_from` to the end of the run. That start is the detected steady time, or "
       "the second half of the run when migration never became steady. All keys from "
       "`channel_average_from` on are absent if nothing was averaged.",
       {
           {sk::channel_H_over_a, "1",
            "width H over the disc radius a, between the surfaces of the two wall rows "
            "(`channel.h_over_a`)"},
           {sk::channel_phi_bulk, "1",
            "the imposed bulk areal fraction phi_b over Lx H (`channel.phi`)"},
           {sk::channel_mean_velocity, "P d / eta",
            "the mean fluid velocity <u> held fixed (`channel.mean_velocity`)"},
           {sk::channel_coupling, "-",
            "\"two_way\" (the fluid profile and the pressure gradient are solved with the "
            "particles) or \"one_way\" (a fixed Poiseuille profile)"},
           {sk::channel_pressure_gradient_poiseuille, "P / d",
            "G0 = 12 eta <u> / H^2, the pressure gradient of the pure fluid at the same <u>"},
           {sk::channel_history_file, "-",
            "\"channel.h5\", the file that holds the migration's history"},
           {sk::channel_steady, "bool",
            "whether the migration's steady state was detected (the mean centreline distance "
            "differs by less than `channel.steady_tolerance` between the halves of the last "
            "`channel.steady_window`)"},
           {sk::channel_steady_time, "a/<u>",
            "midpoint of that window at detection; null if never steady"},
           {sk::channel_average_from, "a/<u>", "start of the averages below"},
           {sk::channel_y, "H", "array: bin centres, y/H from the bottom row's surface"},
           {sk::channel_phi, "1",
            "array: areal fraction per bin (each disc's exact area in each bin)"},
           {sk::channel_u_p, "<u>",
            "array: particle x velocity per bin, weighted by disc area in the bin"},
           {sk::channel_u_f, "<u>", "array: fluid velocity U_f at the bin centre"},
           {sk::channel_T_time, "<u>^2 (a/H)^2",
            "array: suspension temperature <u'.u'> about the time-averaged mean of the bin; discs "
            "within 0.01 a of a wall disc left out"},
           {sk::channel_T_instant, "<u>^2 (a/H)^2",
            "array: the same about the bin's instantaneous mean (the seed's choice)"},
           {sk::channel_u_c, "<u>",
            "u_p at the centreline: mean of the two centre bins (seed's u_c)"},
           {sk::channel_phi_c, "1", "phi at the centreline, the same way (seed's phi_c)"},
           {sk::channel_u_p_mean, "<u>",
            "average of channel_u_p over the bins holding discs (the seed's u_p, Table 1 column "
            "9)"},
           {sk::channel_Q_p, "1",
            "particle flux mean(phi u_p) / phi_b over the bins (seed column 10)"},
           {sk::channel_dp_ratio, "1",
            "time mean of G / G0 (seed column 11; 1 by construction with one-way coupling)"},
           {sk::channel_centre_distance, "d",
            "time mean of the mobile discs' mean distance from the centreline"},
           {sk::channel_mean_particle_velocity, "<u>",
            "time mean of the mobile discs' mean x velocity; differs from 1 by the phase slip"},
       }},
      {"Keys of older runs",
       "Stored summaries written by earlier versions may hold keys the current code no longer "
       "writes:",
       {
           {sk::D_stderr, "gammadot d^2",
            "the former name of `D_regression_stderr` (before the time-block errors)"},
           {sk::channel_history, "-",
            "the channel history, now in channel.h5 (runs before 2026-12-02)"},
       }},
  };
}

namespace {

// A paragraph in lines of at most 100 columns (the docs' width).
std::string wrapped(const std::string& text) {
  std::string out, line, word;
  std::istringstream words(text);
  while (words >> word) {
    if (!line.empty() && line.size() + 1 + word.size() > 100) out += line + "\n", line.clear();
    line += (line.empty() ? "" : " ") + word;
  }
  return out + line + "\n";
}

}  // namespace

std::string summary_keys_markdown() {
  std::string md;
  for (const auto& g : summary_key_groups()) {
    md += fmt::format("### {}\n\n", g.title);
    if (!g.intro.empty()) md += wrapped(g.intro) + "\n";
    md += "| key | unit | meaning |\n|---|---|---|\n";
    for (const auto& k : g.keys)
      md += fmt::format("| `{}` | {} | {} |\n", k.name, k.unit, k.meaning);
    md += "\n";
  }
  md.pop_back();
  return md;
}

nlohmann::json summary_keys_json() {
  auto list = nlohmann::json::array();
  for (const auto& g : summary_key_groups())
    for (const auto& k : g.keys)
      list.push_back(
          {{"key", k.name}, {"unit", k.unit}, {"meaning", k.meaning}, {"group", g.title}});
  return list;
}

}  // namespace sheardiff
