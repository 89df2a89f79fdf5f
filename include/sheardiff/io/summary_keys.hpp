#pragma once
// Every key a run writes to summary.json, declared once. The writers, the result printer and the
// sweep collector use these names; their units and meanings are the rows of
// src/io/summary_keys.cpp, from which `sheardiff summary-keys --markdown` prints the tables of
// docs/outputs.md and
// `--json` the list the Python tools check against (tools/rundir.py reads this file). A ctest runs
// each scene and fails on a key it writes that is not declared here.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace sheardiff {

namespace summary_key {

// Every run: identity, cost and health (src/run_parts.cpp, src/observe/run_health.cpp; analysed_*
// by `sheardiff analyse`)
inline constexpr const char* version = "version";
inline constexpr const char* git_hash = "git_hash";
inline constexpr const char* host = "host";
inline constexpr const char* blas_kernels = "blas_kernels";
inline constexpr const char* seed = "seed";
inline constexpr const char* started = "started";
inline constexpr const char* finished = "finished";
inline constexpr const char* scene = "scene";
inline constexpr const char* dimension = "dimension";
inline constexpr const char* N = "N";
inline constexpr const char* J = "J";
inline constexpr const char* ktilde = "ktilde";
inline constexpr const char* integrator = "integrator";
inline constexpr const char* strain = "strain";
inline constexpr const char* steps = "steps";
inline constexpr const char* steps_per_strain = "steps_per_strain";
inline constexpr const char* wall_seconds = "wall_seconds";
inline constexpr const char* ms_per_step = "ms_per_step";
inline constexpr const char* neighbour_rebuilds = "neighbour_rebuilds";
inline constexpr const char* factorisations = "factorisations";
inline constexpr const char* sticking_resolves_per_step = "sticking_resolves_per_step";
inline constexpr const char* dt_limited_by = "dt_limited_by";
inline constexpr const char* lx = "lx";
inline constexpr const char* ly = "ly";
inline constexpr const char* health = "health";
inline constexpr const char* analysed_by = "analysed_by";
inline constexpr const char* analysed_with = "analysed_with";

// The rheology (src/observe/observer.cpp (RheologyObserver))
inline constexpr const char* averaged_from_strain = "averaged_from_strain";
inline constexpr const char* shear_stress = "shear_stress";
inline constexpr const char* pressure = "pressure";
inline constexpr const char* viscosity = "viscosity";
inline constexpr const char* contacts_per_particle = "contacts_per_particle";
inline constexpr const char* mean_overlap = "mean_overlap";
inline constexpr const char* max_overlap = "max_overlap";
inline constexpr const char* phi = "phi";

// The pressure cell: steady state and window means (src/observe/pressure_cell.cpp)
inline constexpr const char* steady = "steady";
inline constexpr const char* steady_strain = "steady_strain";
inline constexpr const char* steady_detected_at = "steady_detected_at";
inline constexpr const char* measured_strain = "measured_strain";
inline constexpr const char* note = "note";
inline constexpr const char* H = "H";
inline constexpr const char* H_err = "H_err";
inline constexpr const char* phi_err = "phi_err";
inline constexpr const char* phi_std = "phi_std";
inline constexpr const char* mu = "mu";
inline constexpr const char* mu_err = "mu_err";
inline constexpr const char* mu_top = "mu_top";
inline constexpr const char* mu_top_err = "mu_top_err";
inline constexpr const char* mu_bottom = "mu_bottom";
inline constexpr const char* mu_bottom_err = "mu_bottom_err";
inline constexpr const char* steady_errors_note = "steady_errors_note";
inline constexpr const char* pressure_measured = "pressure_measured";
inline constexpr const char* pressure_max_relative_error = "pressure_max_relative_error";
inline constexpr const char* wall_free_fall_steps = "wall_free_fall_steps";

// The pressure cell: stationarity of the measured window (src/observe/pressure_cell.cpp)
inline constexpr const char* stationary = "stationary";
inline constexpr const char* not_stationary = "not_stationary";
inline constexpr const char* stationarity_warning = "stationarity_warning";
inline constexpr const char* net_drag_y = "net_drag_y";
inline constexpr const char* net_drag_y_err = "net_drag_y_err";
inline constexpr const char* mu_top_minus_bottom = "mu_top_minus_bottom";
inline constexpr const char* mu_top_minus_bottom_err = "mu_top_minus_bottom_err";
inline constexpr const char* H_change = "H_change";
inline constexpr const char* H_change_err = "H_change_err";
inline constexpr const char* bulk_normal_load = "bulk_normal_load";
inline constexpr const char* bulk_normal_load_err = "bulk_normal_load_err";
inline constexpr const char* window_blocks = "window_blocks";

// The pressure cell: profiles across the gap (src/observe/profiles.cpp)
inline constexpr const char* profile_bin = "profile_bin";
inline constexpr const char* profile_y = "profile_y";
inline constexpr const char* profile_phi = "profile_phi";
inline constexpr const char* profile_u_x = "profile_u_x";
inline constexpr const char* profile_T = "profile_T";
inline constexpr const char* profile_shear_stress = "profile_shear_stress";
inline constexpr const char* profile_pressure = "profile_pressure";
inline constexpr const char* profile_shear_stress_lubrication = "profile_shear_stress_lubrication";
inline constexpr const char* profile_pressure_lubrication = "profile_pressure_lubrication";
inline constexpr const char* bulk_shear_rate_ratio = "bulk_shear_rate_ratio";
inline constexpr const char* profiles_from = "profiles_from";

// The diffusion analysis (src/analysis/diffusion.cpp, src/observe/diffusion_observer.cpp)
inline constexpr const char* D = "D";
inline constexpr const char* D_err = "D_err";
inline constexpr const char* D_regression_stderr = "D_regression_stderr";
inline constexpr const char* D_all_reference_times = "D_all_reference_times";
inline constexpr const char* D_x = "D_x";
inline constexpr const char* msd_x_window_slope = "msd_x_window_slope";
inline constexpr const char* velocity_intervals = "velocity_intervals";
inline constexpr const char* dv_intervals = "dv_intervals";
inline constexpr const char* dv_intervals_err = "dv_intervals_err";
inline constexpr const char* psi_intervals = "psi_intervals";
inline constexpr const char* psi_intervals_err = "psi_intervals_err";
inline constexpr const char* D_bulk = "D_bulk";
inline constexpr const char* dv = "dv";
inline constexpr const char* dv_err = "dv_err";
inline constexpr const char* dv_bulk = "dv_bulk";
inline constexpr const char* dv_bulk_err = "dv_bulk_err";
inline constexpr const char* psi = "psi";
inline constexpr const char* psi_err = "psi_err";
inline constexpr const char* psi_e = "psi_e";
inline constexpr const char* psi_e_err = "psi_e_err";
inline constexpr const char* psi_zero = "psi_zero";
inline constexpr const char* psi_zero_err = "psi_zero_err";
inline constexpr const char* psi_full = "psi_full";
inline constexpr const char* psi_full_err = "psi_full_err";
inline constexpr const char* psi_bulk = "psi_bulk";
inline constexpr const char* psi_bulk_err = "psi_bulk_err";
inline constexpr const char* psi_e_bulk = "psi_e_bulk";
inline constexpr const char* psi_full_bulk = "psi_full_bulk";
inline constexpr const char* psi_from_D = "psi_from_D";
inline constexpr const char* step_length = "step_length";
inline constexpr const char* diffusion_consistency = "diffusion_consistency";
inline constexpr const char* msd_window = "msd_window";
inline constexpr const char* msd_window_slope = "msd_window_slope";
inline constexpr const char* error_block_strain = "error_block_strain";
inline constexpr const char* error_blocks = "error_blocks";
inline constexpr const char* bulk_fraction = "bulk_fraction";
inline constexpr const char* analysis_samples = "analysis_samples";
inline constexpr const char* analysis_sample_strain = "analysis_sample_strain";
inline constexpr const char* analysis_coarse_strain = "analysis_coarse_strain";
inline constexpr const char* analysis_warnings = "analysis_warnings";

// The channel (src/observe/channel.cpp)
inline constexpr const char* channel_H_over_a = "channel_H_over_a";
inline constexpr const char* channel_phi_bulk = "channel_phi_bulk";
inline constexpr const char* channel_mean_velocity = "channel_mean_velocity";
inline constexpr const char* channel_coupling = "channel_coupling";
inline constexpr const char* channel_pressure_gradient_poiseuille =
    "channel_pressure_gradient_poiseuille";
inline constexpr const char* channel_history_file = "channel_history_file";
inline constexpr const char* channel_steady = "channel_steady";
inline constexpr const char* channel_steady_time = "channel_steady_time";
inline constexpr const char* channel_average_from = "channel_average_from";
inline constexpr const char* channel_y = "channel_y";
inline constexpr const char* channel_phi = "channel_phi";
inline constexpr const char* channel_u_p = "channel_u_p";
inline constexpr const char* channel_u_f = "channel_u_f";
inline constexpr const char* channel_T_time = "channel_T_time";
inline constexpr const char* channel_T_instant = "channel_T_instant";
inline constexpr const char* channel_u_c = "channel_u_c";
inline constexpr const char* channel_phi_c = "channel_phi_c";
inline constexpr const char* channel_u_p_mean = "channel_u_p_mean";
inline constexpr const char* channel_Q_p = "channel_Q_p";
inline constexpr const char* channel_dp_ratio = "channel_dp_ratio";
inline constexpr const char* channel_centre_distance = "channel_centre_distance";
inline constexpr const char* channel_mean_particle_velocity = "channel_mean_particle_velocity";

// Keys of older runs (no longer written; read by tools/channel_history_to_h5.py)
inline constexpr const char* D_stderr = "D_stderr";
inline constexpr const char* channel_history = "channel_history";

}  // namespace summary_key

// One documented key: its name (a summary_key constant), unit (docs/units.md) and meaning.
struct SummaryKeyDoc {
  const char* name;
  const char* unit;
  std::string meaning;
};

// The keys one part of the code writes, with the paragraph that introduces them in the docs.
struct SummaryKeyGroup {
  std::string title;
  std::string intro;
  std::vector<SummaryKeyDoc> keys;
};

// Every declared key, by group, in the order of docs/outputs.md.
std::vector<SummaryKeyGroup> summary_key_groups();

// The tables of docs/outputs.md ("### title", intro, | key | unit | meaning |).
std::string summary_keys_markdown();

// Every declared key as {key, unit, meaning, group}, for tools.
nlohmann::json summary_keys_json();

}  // namespace sheardiff
