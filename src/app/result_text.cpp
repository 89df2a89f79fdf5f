#include "result_text.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>

#include "sheardiff/io/summary_keys.hpp"

namespace sheardiff {

namespace {

// A summary value, NaN when absent or not a number: summaries of older versions or of runs
// that ended early lack some keys, and printing must not abort on them.
double num(const nlohmann::json& js, const char* key) {
  const auto it = js.find(key);
  return it != js.end() && it->is_number() ? it->get<double>() : NAN;
}
double num_at(const nlohmann::json& js, const char* key, std::size_t i) {
  const auto it = js.find(key);
  return it != js.end() && it->is_array() && i < it->size() && (*it)[i].is_number()
             ? (*it)[i].get<double>()
             : NAN;
}
bool flag(const nlohmann::json& js, const char* key) {
  const auto it = js.find(key);
  return it != js.end() && it->is_boolean() && it->get<bool>();
}
long count(const nlohmann::json& js, const char* key) {
  const auto it = js.find(key);
  return it != js.end() && it->is_number() ? it->get<long>() : 0L;
}

// The measured window's stationarity signals, one line, and what failed.
std::string stationarity_text(const nlohmann::json& js) {
  return fmt::format(
      "  stationarity of the window: net y drag {:.3g} +- {:.2g} P, mu_top - mu_bottom {:.3g} +- "
      "{:.2g}, H change {:.3g} +- {:.2g} d, bulk normal load {:.4f} +- {:.2g} P: {}\n",
      num(js, summary_key::net_drag_y), num(js, summary_key::net_drag_y_err),
      num(js, summary_key::mu_top_minus_bottom), num(js, summary_key::mu_top_minus_bottom_err),
      num(js, summary_key::H_change), num(js, summary_key::H_change_err),
      num(js, summary_key::bulk_normal_load), num(js, summary_key::bulk_normal_load_err),
      flag(js, summary_key::stationary) ? "stationary" : "DRIFTING");
}

}  // namespace

std::string run_result_first_line(const nlohmann::json& summary, const std::string& out_dir) {
  return fmt::format(
      "{}: strain {:.4g} in {} steps, {:.1f} s ({:.3g} ms/step); max overlap {:.3g} d\n", out_dir,
      num(summary, summary_key::strain), count(summary, summary_key::steps),
      num(summary, summary_key::wall_seconds), num(summary, summary_key::ms_per_step),
      num(summary, summary_key::max_overlap));
}

std::string run_result_details(const nlohmann::json& summary) {
  std::string details;
  if (summary.contains(summary_key::channel_coupling)) {
    // The channel's time is in a / <u> and its pressure scale is the flow's, not P: its own lines.
    const std::string steady =
        flag(summary, summary_key::channel_steady)
            ? fmt::format("migration steady from t = {:.4g} a/<u>",
                          num(summary, summary_key::channel_steady_time))
            : fmt::format("migration NOT steady: averaged from t = {:.4g} a/<u> (half the run)",
                          num(summary, summary_key::channel_average_from));
    details += fmt::format("  {}\n", steady);
    details += fmt::format(
        "  u_c = {:.3f} <u>, phi_c = {:.3f}, u_p = {:.3f} <u>, Q_p = {:.3f}, pressure gradient "
        "{:.3f} x Poiseuille's ({} coupling)\n",
        num(summary, summary_key::channel_u_c), num(summary, summary_key::channel_phi_c),
        num(summary, summary_key::channel_u_p_mean), num(summary, summary_key::channel_Q_p),
        num(summary, summary_key::channel_dp_ratio),
        summary[summary_key::channel_coupling].is_string()
            ? summary[summary_key::channel_coupling].get<std::string>()
            : std::string("?"));
    return details;
  }
  if (summary.contains(summary_key::steady)) {
    if (!flag(summary, summary_key::steady)) {
      details +=
          fmt::format("  steady state NOT reached (H or mu still drift); phi(now) = {:.4f}\n",
                      num(summary, summary_key::phi));
    } else {
      // An error bar that could not be formed is said so, never printed as "+- nan".
      const auto pm = [&](const char* key) {
        const double e = num(summary, key);
        return std::isfinite(e) ? fmt::format(" +- {:.2g}", e) : std::string(" (no error bar)");
      };
      details += fmt::format(
          "  steady at strain {:.4g}, measured over {:.3g} strains: phi = {:.4f}{}, mu = {:.4f}{}, "
          "H = {:.3f} d ({})\n",
          num(summary, summary_key::steady_detected_at), num(summary, summary_key::measured_strain),
          num(summary, summary_key::phi), pm(summary_key::phi_err), num(summary, summary_key::mu),
          pm(summary_key::mu_err), num(summary, summary_key::H),
          summary.contains(summary_key::steady_errors_note)
              ? summary[summary_key::steady_errors_note].get<std::string>()
              : std::string("+- statistical errors, time blocks"));
      details += fmt::format(
          "  wall pressure check: measured {:.12f} P (max relative error {:.2e} over {} "
          "held steps)\n",
          num(summary, summary_key::pressure_measured),
          num(summary, summary_key::pressure_max_relative_error),
          count(summary, summary_key::steps) - count(summary, summary_key::wall_free_fall_steps));
      if (summary.contains(summary_key::stationary)) details += stationarity_text(summary);
    }
  } else if (std::isnan(num(summary, summary_key::shear_stress))) {
    details += fmt::format("  no averages: the run ended before run.transient_strain\n");
  } else {
    details +=
        fmt::format("  shear stress {:.5g} P, particle pressure {:.5g} P, viscosity {:.4g} eta\n",
                    num(summary, summary_key::shear_stress), num(summary, summary_key::pressure),
                    num(summary, summary_key::viscosity));
  }
  if (summary.contains(summary_key::D))
    details += fmt::format(
        "  diffusion: D = {:.4g} +- {:.2g} gammadot d^2 (MSD window [{:g}, {:g}]), dv = {:.4g} "
        "+- {:.2g} gammadot d, Psi = {:.4g} +- {:.2g} / gammadot\n",
        num(summary, summary_key::D), num(summary, summary_key::D_err),
        num_at(summary, summary_key::msd_window, 0), num_at(summary, summary_key::msd_window, 1),
        num(summary, summary_key::dv), num(summary, summary_key::dv_err),
        num(summary, summary_key::psi), num(summary, summary_key::psi_err));
  return details;
}

std::string analysis_result_text(const nlohmann::json& js, const std::string& run_dir) {
  return fmt::format(
      "{}: D = {:.4g} +- {:.2g} gammadot d^2 over strain window [{:g}, {:g}] "
      "(log-log slope {:.3f}); dv = {:.4g} +- {:.2g} gammadot d; Psi = {:.4g} +- {:.2g} / "
      "gammadot; step length {:.4g} d\n",
      run_dir, num(js, summary_key::D), num(js, summary_key::D_err),
      num_at(js, summary_key::msd_window, 0), num_at(js, summary_key::msd_window, 1),
      num(js, summary_key::msd_window_slope), num(js, summary_key::dv),
      num(js, summary_key::dv_err), num(js, summary_key::psi), num(js, summary_key::psi_err),
      num(js, summary_key::step_length));
}

void print_warnings(const nlohmann::json& js) {
  if (const auto w = js.find(summary_key::stationarity_warning); w != js.end() && w->is_string())
    fmt::print(stderr, "warning: {}\n", w->get<std::string>());
  const auto it = js.find(summary_key::analysis_warnings);
  if (it == js.end() || !it->is_array()) return;
  for (const auto& w : *it)
    if (w.is_string()) fmt::print(stderr, "warning: {}\n", w.get<std::string>());
}

}  // namespace sheardiff
