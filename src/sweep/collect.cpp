// Collecting a sweep: one sweep.csv row per point (all summary.json keys) and fits.json (the
// seed's power laws per group of points that differ only in J and seed).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include "sheardiff/analysis/power_law.hpp"
#include "sheardiff/config.hpp"
#include "sheardiff/core/text.hpp"
#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/summary_keys.hpp"
#include "sheardiff/sweep/sweep.hpp"

namespace sheardiff {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

bool is_seed_axis(const std::string& key) {
  return key.ends_with(".seed");
}

std::string csv_cell(const json& v) {
  if (v.is_null()) return "";
  if (v.is_number_float()) return fmt::format("{}", v.get<double>());
  if (v.is_number()) return v.dump();
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  std::string s = v.is_string() ? v.get<std::string>() : v.dump();
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// sweep.csv: one line of column names, then one line per row (empty cells where a row lacks
// a column).
std::string csv_text(const std::vector<std::string>& columns,
                     const std::vector<std::map<std::string, json>>& table) {
  std::ostringstream csv;
  csv << fmt::format("{}\n", fmt::join(columns, ","));
  for (const auto& row : table) {
    std::vector<std::string> cells;
    for (const auto& c : columns) {
      auto it = row.find(c);
      cells.push_back(it == row.end() ? "" : csv_cell(it->second));
    }
    csv << fmt::format("{}\n", fmt::join(cells, ","));
  }
  return csv.str();
}

// The rows of a sweep.csv written by csv_text, each cell as its text, by column name.
std::vector<std::map<std::string, std::string>> read_csv_rows(const fs::path& file) {
  std::ifstream in(file);
  std::string text(std::istreambuf_iterator<char>(in), {});
  std::vector<std::vector<std::string>> lines(1);
  std::string cell;
  bool quoted = false;
  for (std::size_t k = 0; k < text.size(); ++k) {
    const char c = text[k];
    if (quoted) {
      if (c == '"' && k + 1 < text.size() && text[k + 1] == '"')
        cell += '"', ++k;
      else if (c == '"')
        quoted = false;
      else
        cell += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      lines.back().push_back(std::move(cell)), cell.clear();
    } else if (c == '\n') {
      lines.back().push_back(std::move(cell)), cell.clear();
      lines.emplace_back();
    } else {
      cell += c;
    }
  }
  std::vector<std::map<std::string, std::string>> rows;
  for (std::size_t r = 1; r < lines.size(); ++r) {
    if (lines[r].size() != lines[0].size()) continue;
    std::map<std::string, std::string> row;
    for (std::size_t c = 0; c < lines[0].size(); ++c) row[lines[0][c]] = lines[r][c];
    rows.push_back(std::move(row));
  }
  return rows;
}

// A summary flattened to scalars: arrays become key_0, key_1, ...
void flatten(const json& summary, std::map<std::string, json>& row) {
  for (const auto& [k, v] : summary.items()) {
    if (v.is_array()) {
      if (v.size() <= 4 &&
          std::all_of(v.begin(), v.end(), [](const json& e) { return e.is_primitive(); }))
        for (size_t i = 0; i < v.size(); ++i) row[fmt::format("{}_{}", k, i)] = v[i];
      else
        row[k] = v.dump();
    } else if (v.is_object()) {
      row[k] = v.dump();
    } else {
      row[k] = v;
    }
  }
}

// The status of a finished run whose measurement cannot be fitted, or "" if it can: a pressure
// cell that never reached steady state has no phi(J) or mu(J), and one whose measured window
// drifted (or was too short to judge) measured a transient.
std::string window_verdict(const json& summary) {
  const auto is_false = [&](const char* key) {
    return summary.contains(key) && summary[key].is_boolean() && !summary[key].get<bool>();
  };
  if (is_false(summary_key::steady)) return "done, not steady";
  if (is_false(summary_key::stationary)) return "done, not stationary";
  return "";
}

double num(const json& s, const char* key) {
  if (!s.contains(key) || !s[key].is_number()) return NAN;
  return s[key].get<double>();
}

json law_json(const PowerLawFit& f) {
  return {{"a", f.a},  {"a_stderr", f.a_stderr}, {"b", f.b}, {"b_stderr", f.b_stderr}, {"n", f.n},
          {"r2", f.r2}};
}

// Fits y = a x^b over the rows where both are finite and positive; {"error": ...} otherwise.
json power_fit(const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<double> xs, ys;
  for (size_t i = 0; i < x.size(); ++i)
    if (std::isfinite(x[i]) && std::isfinite(y[i]) && x[i] > 0 && y[i] > 0) {
      xs.push_back(x[i]);
      ys.push_back(y[i]);
    }
  try {
    return law_json(fit_power_law(xs, ys));
  } catch (const std::invalid_argument& e) {
    return {{"error", e.what()}, {"n", xs.size()}};
  }
}

// phi_c - a x^b (sign = +1) or, for mu(J) = mu_c + a x^b, the same fit of -mu (sign = -1).
json dilatancy_fit(const std::vector<double>& x, const std::vector<double>& y, double sign,
                   const char* critical) {
  std::vector<double> xs, ys;
  for (size_t i = 0; i < x.size(); ++i)
    if (std::isfinite(x[i]) && std::isfinite(y[i]) && x[i] > 0) {
      xs.push_back(x[i]);
      ys.push_back(sign * y[i]);
    }
  try {
    const auto f = fit_dilatancy(xs, ys);
    return {{critical, sign * f.phi_c},
            {std::string(critical) + "_stderr", f.phi_c_stderr},
            {std::string(critical) + "_err_seed", f.phi_c_err},
            {"a", f.law.a},
            {"b", f.law.b},
            {"a_stderr", f.a_stderr_joint},
            {"b_stderr", f.b_stderr_joint},
            {"a_stderr_seed", f.law.a_stderr},
            {"b_stderr_seed", f.law.b_stderr},
            {"n", f.law.n},
            {"r2", f.law.r2}};
  } catch (const std::invalid_argument& e) {
    return {{"error", e.what()}, {"n", xs.size()}};
  }
}

// Seed Table 1 (suspensions) and eq. (3.3)/(3.4), for side-by-side reading.
json seed_reference() {
  const auto law = [](double a, double ae, double b, double be) {
    return json{{"a", a}, {"a_stderr", ae}, {"b", b}, {"b_stderr", be}};
  };
  return {{"D_vs_J", law(0.024, 0.002, -0.26, 0.02)},
          {"dv_vs_J", law(0.258, 0.008, -0.25, 0.04)},
          {"psi_vs_J", law(0.35, 0.02, 0.24, 0.02)},
          {"D_vs_phic_minus_phi", law(0.019, 0.006, -0.61, 0.1)},
          {"dv_vs_phic_minus_phi", law(0.25, 0.01, -0.54, 0.07)},
          {"psi_vs_phic_minus_phi", law(0.37, 0.06, 0.51, 0.06)},
          {"phi_of_J", json{{"phi_c", 0.81}, {"a", 0.64}, {"b", 0.5}}}};
}

}  // namespace

json fit_group(const std::vector<json>& rows) {
  std::vector<double> J, phi, mu, D, dv, psi;
  for (const auto& r : rows) {
    J.push_back(num(r, summary_key::J));
    phi.push_back(num(r, summary_key::phi));
    mu.push_back(num(r, summary_key::mu));
    D.push_back(num(r, summary_key::D));
    dv.push_back(num(r, summary_key::dv));
    psi.push_back(num(r, summary_key::psi));
  }
  json fits;
  fits["D_vs_J"] = power_fit(J, D);
  fits["dv_vs_J"] = power_fit(J, dv);
  fits["psi_vs_J"] = power_fit(J, psi);
  fits["phi_of_J"] = dilatancy_fit(J, phi, +1.0, "phi_c");
  fits["mu_of_J"] = dilatancy_fit(J, mu, -1.0, "mu_c");
  if (fits["phi_of_J"].contains("phi_c")) {
    const double phi_c = fits["phi_of_J"]["phi_c"].get<double>();
    std::vector<double> x;
    for (double p : phi) x.push_back(phi_c - p);
    fits["D_vs_phic_minus_phi"] = power_fit(x, D);
    fits["dv_vs_phic_minus_phi"] = power_fit(x, dv);
    fits["psi_vs_phic_minus_phi"] = power_fit(x, psi);
  } else {
    const json why = {{"error", "no phi_c: the phi(J) fit failed"}};
    fits["D_vs_phic_minus_phi"] = fits["dv_vs_phic_minus_phi"] = fits["psi_vs_phic_minus_phi"] =
        why;
  }
  return fits;
}

// Fit errors from the scatter between seeds: every replicate draws, at each J, as many runs as
// there are with replacement, averages them, and refits. Returns {fit: {param: sd}} over the
// replicates (null where a fit failed in more than 5 % of them or there is one run per J).
// The plain bootstrap's variance of an n-run mean is (n - 1)/n times the unbiased s^2/n: half
// of it with the two or three seeds a sweep affords. So each J's runs are drawn about their mean
// with deviations widened by sqrt(n / (n - 1)), which makes a replicate mean's variance s^2/n.
json seed_bootstrap(const std::map<double, std::vector<json>>& by_j, long replicates) {
  bool several = false;
  for (const auto& [j, runs] : by_j) several = several || runs.size() > 1;
  if (!several) return json::object();
  std::mt19937_64 rng(20261201);
  std::map<std::string, std::vector<double>> samples;
  const char* params[] = {"a", "b", "phi_c", "mu_c"};
  long done = 0;
  for (long r = 0; r < replicates; ++r) {
    std::vector<json> rows;
    for (const auto& [j, runs] : by_j) {
      json row{{"J", j}};
      std::vector<std::size_t> pick;
      for (std::size_t k = 0; k < runs.size(); ++k) pick.push_back(rng() % runs.size());
      for (const char* q :
           {summary_key::phi, summary_key::mu, summary_key::D, summary_key::dv, summary_key::psi}) {
        double mean = 0;
        long n_all = 0;
        for (const auto& run : runs)
          if (const double v = num(run, q); std::isfinite(v)) mean += v, ++n_all;
        mean /= static_cast<double>(std::max(n_all, 1L));
        const double widen =
            n_all > 1 ? std::sqrt(static_cast<double>(n_all) / static_cast<double>(n_all - 1))
                      : 1.0;
        double sum = 0;
        long n = 0;
        for (std::size_t k : pick)
          if (const double v = num(runs[k], q); std::isfinite(v))
            sum += mean + widen * (v - mean), ++n;
        row[q] = n > 0 ? json(sum / static_cast<double>(n)) : json(nullptr);
      }
      rows.push_back(row);
    }
    const json fits = fit_group(rows);
    ++done;
    for (const auto& [name, f] : fits.items())
      for (const char* q : params)
        if (f.contains(q) && f[q].is_number())
          samples[name + "." + q].push_back(f[q].get<double>());
  }
  json out = json::object();
  for (const auto& [key, v] : samples) {
    const auto dot = key.find('.');
    const std::string fit = key.substr(0, dot), param = key.substr(dot + 1);
    if (static_cast<double>(v.size()) < 0.95 * static_cast<double>(done)) {
      out[fit][param] = nullptr;
      continue;
    }
    double m = 0, s2 = 0;
    for (double x : v) m += x / static_cast<double>(v.size());
    for (double x : v) s2 += (x - m) * (x - m);
    out[fit][param] = std::sqrt(s2 / static_cast<double>(v.size() - 1));
  }
  return out;
}

namespace {

// One group's entry of fits.json: the runs averaged over seeds at each J, the seed's laws
// fitted to the means, errors from the seed bootstrap.
json fits_of_group(const std::map<double, std::vector<json>>& by_j, const json& axes) {
  // Seeds averaged at each J (standard error of their mean where there are several).
  std::vector<json> rows;
  for (const auto& [j, runs] : by_j) {
    json r{{"J", j}, {"runs", runs.size()}};
    for (const char* q : {summary_key::phi, summary_key::mu, summary_key::D, summary_key::dv,
                          summary_key::psi, summary_key::H}) {
      double s = 0, s2 = 0;
      long n = 0;
      for (const auto& run : runs) {
        const double v = num(run, q);
        if (!std::isfinite(v)) continue;
        s += v;
        s2 += v * v;
        ++n;
      }
      if (n == 0) {
        r[q] = nullptr;
        continue;
      }
      const double mean = s / n;
      r[q] = mean;
      // The scatter between seeds (null with one seed), and what the runs' own error bars
      // predict for it (their rms over sqrt(n)): the two agree if the error bars are right.
      r[std::string(q) + "_sem"] =
          n > 1 ? json(std::sqrt(std::max(0.0, (s2 - n * mean * mean) / (n - 1)) / n))
                : json(nullptr);
      double e2 = 0;
      long ne = 0;
      for (const auto& run : runs)
        if (const double e = num(run, (std::string(q) + "_err").c_str()); std::isfinite(e))
          e2 += e * e, ++ne;
      r[std::string(q) + "_run_err"] =
          ne > 0 ? json(std::sqrt(e2 / ne) / std::sqrt(static_cast<double>(ne))) : json(nullptr);
    }
    rows.push_back(r);
  }
  json laws = fit_group(rows);
  // Quoted errors: the seed bootstrap's; the regressions' own stay as *_regression_stderr.
  const json boot = seed_bootstrap(by_j, 2000);
  for (auto& [name, f] : laws.items()) {
    if (f.contains("error")) continue;
    for (const char* q : {"a", "b", "phi_c", "mu_c"}) {
      const std::string se = std::string(q) + "_stderr";
      if (!f.contains(q)) continue;
      if (f.contains(se)) f[std::string(q) + "_regression_stderr"] = f[se];
      f[se] = boot.contains(name) && boot[name].contains(q) ? boot[name][q] : json(nullptr);
    }
    f["errors"] = boot.contains(name) ? "seed bootstrap" : "none: one seed per J";
  }
  return {{"axes", axes}, {"rows", rows}, {"fits", laws}};
}

}  // namespace

namespace {

using Row = std::map<std::string, json>;

// What a collection gathers: sweep.csv's rows and columns, and the finished measurements grouped
// by the axes other than J and the seeds (within a group, by J).
struct Collection {
  std::vector<Row> table;
  std::set<std::string> summary_keys, kept_axes;
  std::map<std::string, std::map<double, std::vector<json>>> groups;
  std::map<std::string, json> group_axes;
  long finished = 0, kept = 0;

  // The summary's keys into the row; a measurement that passed its window's test into its group.
  void add_summary(Row& row, const json& summary, const std::string& group_key, const json& axes,
                   bool placed) {
    std::map<std::string, json> flat;
    flatten(summary, flat);
    for (auto& [k, v] : flat) summary_keys.insert(k), row[k] = v;
    const std::string verdict = window_verdict(summary);
    if (!verdict.empty()) row["status"] = verdict;
    if (placed && verdict.empty() && summary.contains(summary_key::J)) {
      groups[group_key][summary[summary_key::J].get<double>()].push_back(summary);
      group_axes[group_key] = axes;
    } else if (placed) {
      group_axes[group_key] = axes;
    }
  }
};

struct PointResult {
  std::string status = "missing";
  json summary;
};

// A finished run directory is stored first; a point finished elsewhere is read from the store.
// A finished point whose config differs from the sweep's is an error, not a row.
PointResult point_result(const SweepSpec& spec, const SweepPoint& p, const fs::path& out_dir) {
  PointResult r;
  auto dir = point_dir(out_dir, p);
  const bool here =
      fs::exists(dir / "summary.json") && point_state(spec, p, out_dir) == PointState::finished;
  if (here) export_point(spec, p, out_dir);
  if (!here)
    if (const auto stored = stored_point(spec, p); !stored.empty()) dir = stored;
  if (fs::exists(dir / "summary.json")) {
    if (here || dir != point_dir(out_dir, p)) {
      std::ifstream in(dir / "summary.json");
      r.summary = json::parse(in);
      r.status = "done";
    }
  } else if (fs::exists(out_dir / "logs" / (p.name + ".failed"))) {
    std::ifstream in(out_dir / "logs" / (p.name + ".failed"));
    std::string why;
    std::getline(in, why);
    r.status = "failed: " + why;
  } else if (fs::exists(dir / "checkpoint.bin")) {
    r.status = "unfinished";
  }
  return r;
}

// The point's axis and paired values into its row; its group: the axes other than J and seeds.
void add_listed_point(const SweepSpec& spec, const SweepPoint& p, const fs::path& out_dir,
                      Collection& c) {
  Row row;
  row["point"] = p.name;
  const PointResult r = point_result(spec, p, out_dir);
  row["status"] = r.status;
  std::string group_key;
  json axes = json::object();
  for (const auto& o : p.overrides) {
    const auto eq = o.find('=');
    const std::string key = o.substr(0, eq);
    const bool is_axis = std::any_of(spec.axes.begin(), spec.axes.end(),
                                     [&](const auto& a) { return a.first == key; });
    const bool is_paired = std::any_of(spec.paired.begin(), spec.paired.end(),
                                       [&](const auto& pk) { return pk.key == key; });
    if (is_paired) row["paired." + key] = o.substr(eq + 1);
    if (!is_axis) continue;
    row["axis." + key] = o.substr(eq + 1);
    if (key != "flow.J" && !is_seed_axis(key)) {
      group_key += o + " ";
      axes[key] = json::parse(o.substr(eq + 1), nullptr, false);
    }
  }
  if (r.status == "done") {
    ++c.finished;
    c.add_summary(row, r.summary, group_key, axes, true);
  }
  c.table.push_back(std::move(row));
}

// Finished points in DIR that this sweep file does not list (a sweep over a part of them, or the
// file edited since) stay in DIR's tables: their axis values come from the row the earlier
// collection wrote, their numbers from their own summary. One whose row lacks an axis of this
// sweep is listed but left out of the fits.
void add_kept_points(const SweepSpec& spec, const std::set<std::string>& ours,
                     const fs::path& out_dir, Collection& c) {
  std::map<std::string, std::map<std::string, std::string>> earlier;
  if (fs::exists(out_dir / "sweep.csv"))
    for (auto& r : read_csv_rows(out_dir / "sweep.csv")) earlier[r["point"]] = r;
  std::error_code ec;
  if (!fs::is_directory(out_dir / "points", ec)) return;
  for (const auto& e : fs::directory_iterator(out_dir / "points")) {
    const std::string name = e.path().filename().string();
    if (ours.count(name) || !fs::exists(e.path() / "summary.json")) continue;
    std::ifstream in(e.path() / "summary.json");
    const json summary = json::parse(in, nullptr, false);
    if (summary.is_discarded()) continue;
    Row row;
    row["point"] = name;
    const auto& before = earlier[name];
    for (const auto& [col, text] : before)
      if (col.starts_with("axis.") || col.starts_with("paired."))
        row[col] = text, c.kept_axes.insert(col);
    row["status"] = "done";
    ++c.kept, ++c.finished;
    std::string group_key;
    json axes = json::object();
    bool placed = true;
    for (const auto& [key, values] : spec.axes) {
      if (key == "flow.J" || is_seed_axis(key)) continue;
      const auto it = before.find("axis." + key);
      if (it == before.end() || it->second.empty()) {
        placed = false;
        break;
      }
      group_key += key + "=" + it->second + " ";
      axes[key] = json::parse(it->second, nullptr, false);
    }
    c.add_summary(row, summary, group_key, axes, placed);
    c.table.push_back(std::move(row));
  }
  if (c.kept > 0)
    fmt::print(stderr,
               "sweep: {} finished points in {} lie outside this sweep file's axes: they stay in "
               "its sweep.csv and fits.json\n",
               c.kept, (out_dir / "points").string());
}

// The store's sweep.csv and fits.json stand for every point it holds: a sweep over a part of
// them (one J, one seed, run on another machine) stores its points but leaves those two files to
// a sweep that covers the whole store, instead of replacing them with fits over its part.
bool covers_the_store(const SweepSpec& spec, const std::set<std::string>& ours,
                      const fs::path& out_dir) {
  if (spec.results.empty()) return false;
  if (!fs::is_directory(spec.results / "points")) return true;
  for (const auto& e : fs::directory_iterator(spec.results / "points"))
    if (fs::exists(e.path() / "summary.json") && !ours.count(e.path().filename().string())) {
      fmt::print(stderr,
                 "sweep: {} holds points outside this sweep's axes: its sweep.csv and fits.json "
                 "are left as they were (collect a sweep file covering all of them to refresh "
                 "them); this sweep's are in {}\n",
                 spec.results.string(), out_dir.string());
      return false;
    }
  return true;
}

// sweep.csv: fixed leading columns, then the axes, then every summary key.
std::string sweep_csv(const SweepSpec& spec, const Collection& c) {
  std::vector<std::string> columns = {"point", "status"};
  for (const auto& [key, values] : spec.axes) columns.push_back("axis." + key);
  for (const auto& pk : spec.paired) columns.push_back("paired." + pk.key);
  for (const auto& col : c.kept_axes)
    if (std::find(columns.begin(), columns.end(), col) == columns.end()) columns.push_back(col);
  columns.insert(columns.end(), c.summary_keys.begin(), c.summary_keys.end());
  return csv_text(columns, c.table);
}

json fits_json(const SweepSpec& spec, std::size_t listed, Collection& c) {
  json fits;
  fits["sweep"] = spec.file.filename().string();
  fits["points"] = listed + static_cast<std::size_t>(c.kept);
  fits["finished"] = c.finished;
  // The seed's Table 1 sits beside fits of J-sweeps only: a sweep of another scene (channel
  // cases over seeds) has no J axis to fit and is not that paper's measurement.
  if (!c.groups.empty()) fits["seed_table1"] = seed_reference();
  fits["groups"] = json::array();
  // Each J's seeds in seed order, however their points were found (listed by this sweep file or
  // kept from an earlier one): the seed bootstrap draws by position.
  for (auto& [key, by_j] : c.groups)
    for (auto& [j, runs] : by_j)
      std::stable_sort(runs.begin(), runs.end(), [](const json& a, const json& b) {
        return a.value(summary_key::seed, 0L) < b.value(summary_key::seed, 0L);
      });
  for (const auto& [key, by_j] : c.groups)
    fits["groups"].push_back(fits_of_group(by_j, c.group_axes[key]));
  return fits;
}

}  // namespace

json collect_sweep(const SweepSpec& spec, const fs::path& out_dir) {
  if (!fs::is_directory(out_dir / "points") &&
      (spec.results.empty() || !fs::is_directory(spec.results / "points")))
    throw ConfigError(fmt::format(
        "{}: no sweep there (no points/ folder{})", out_dir.string(),
        spec.results.empty() ? "" : " and no stored results in " + spec.results.string()));
  const auto points = expand_points(spec);
  Collection c;
  std::set<std::string> ours;
  for (const auto& p : points) {
    add_listed_point(spec, p, out_dir, c);
    ours.insert(p.name);
  }
  add_kept_points(spec, ours, out_dir, c);
  const std::string csv = sweep_csv(spec, c);
  fs::create_directories(out_dir);
  write_file_atomically(out_dir / "sweep.csv", csv);
  const bool whole_store = covers_the_store(spec, ours, out_dir);
  if (whole_store) {
    fs::create_directories(spec.results);
    write_file_atomically(spec.results / "sweep.csv", csv);
  }
  const json fits = fits_json(spec, points.size(), c);
  write_file_atomically(out_dir / "fits.json", json_text(fits) + "\n");
  if (whole_store) write_file_atomically(spec.results / "fits.json", json_text(fits) + "\n");
  return fits;
}

namespace {

// Why a finished point's measurement is left out of a combined fit, or "" to keep it.
std::string exclusion(const json& summary, double drift_z) {
  if (const auto verdict = window_verdict(summary); !verdict.empty()) return verdict;
  if (summary.contains(summary_key::stationary)) return "";
  // Written before the stationarity test: of its signals only the walls' mu are stored. Their
  // errors are combined as if independent (the difference's own noise is not stored).
  const double d = num(summary, summary_key::mu_top) - num(summary, summary_key::mu_bottom);
  const double e =
      std::hypot(num(summary, summary_key::mu_top_err), num(summary, summary_key::mu_bottom_err));
  if (!std::isfinite(d) || !std::isfinite(e)) return "";  // no walls: nothing to judge by
  return std::abs(d) > drift_z * e ? "done, drifting (mu_top - mu_bottom)" : "";
}

// What must agree between points fitted as one group (J and the seed vary; the start and the
// run's length may).
std::string group_identity(const Config& c) {
  return fmt::format(
      "scene {}, N = {}, mix {}, size ratio {}, ktilde = {}, kt/kn = {}, mu = {}, "
      "delta = {}, aspect {}",
      c.scene.type, c.particles.n, to_string(c.particles.mix), c.particles.size_ratio,
      c.contact.ktilde, c.contact.kt_ratio, c.contact.mu, c.lubrication.delta, c.particles.aspect);
}

}  // namespace

namespace {

// A store's finished points that measured a J, sorted by folder name.
std::vector<std::pair<fs::path, json>> store_summaries(const fs::path& store) {
  if (!fs::is_directory(store / "points"))
    throw ConfigError(
        fmt::format("fit: {}: not a store or sweep folder (no points/)", store.string()));
  std::vector<fs::path> dirs;
  for (const auto& e : fs::directory_iterator(store / "points"))
    if (fs::exists(e.path() / "summary.json") && fs::exists(e.path() / "config.toml"))
      dirs.push_back(e.path());
  std::sort(dirs.begin(), dirs.end());
  std::vector<std::pair<fs::path, json>> here;
  for (const auto& dir : dirs) {
    std::ifstream in(dir / "summary.json");
    json summary;
    try {
      summary = json::parse(in);
    } catch (const json::exception& e) {
      throw ConfigError(fmt::format("fit: {}: not a valid summary: {}",
                                    (dir / "summary.json").string(), e.what()));
    }
    if (!summary.contains(summary_key::J) || !summary[summary_key::J].is_number()) continue;
    here.emplace_back(dir, std::move(summary));
  }
  return here;
}

// Points of several stores combined into one group: each J from the first store that holds it.
struct Combination {
  bool include_drifting = false;
  std::vector<Row> table;
  std::set<std::string> summary_keys;
  std::map<double, std::vector<json>> by_j;
  std::map<double, std::string> j_from;  // each J's store
  std::string identity, identity_of;
  long used = 0;

  void add(const fs::path& store, const std::string& store_name) {
    std::set<double> js_here;
    for (auto& [dir, summary] : store_summaries(store)) {
      const Config cfg = load_config(dir / "config.toml", {}, ConfigSource::record);
      const std::string id = group_identity(cfg);
      const std::string name =
          (store.filename().empty() ? store.parent_path().filename() : store.filename()).string() +
          "/" + dir.filename().string();
      if (identity.empty()) identity = id, identity_of = name;
      if (id != identity)
        throw ConfigError(fmt::format(
            "fit: {} ({}) and {} ({}) are not one group: fit stores of the same physics", name, id,
            identity_of, identity));
      const double j = summary[summary_key::J].get<double>();
      js_here.insert(j);
      Row row;
      row["point"] = name;
      row["store"] = store_name;
      std::string status = "done";
      if (const auto it = j_from.find(j); it != j_from.end())
        status = "replaced by " + it->second;
      else if (const auto why = exclusion(summary, cfg.steady.drift_z); !why.empty())
        status = why;
      row["status"] = status;
      std::map<std::string, json> flat;
      flatten(summary, flat);
      for (auto& [k, v] : flat) summary_keys.insert(k), row[k] = v;
      // On request, windows flagged by the stationarity test enter the fits too (a check of
      // how much the flagged points move them); replaced and unsteady points never do.
      const bool flagged = status == "done, not stationary" || status.starts_with("done, drifting");
      if (status == "done" || (include_drifting && flagged)) {
        by_j[j].push_back(summary);
        ++used;
      }
      table.push_back(std::move(row));
    }
    for (double j : js_here) j_from.emplace(j, store_name);
  }
};

}  // namespace

json fit_stores(const std::vector<fs::path>& stores, const fs::path& out_dir,
                bool include_drifting) {
  if (stores.empty()) throw ConfigError("fit: give at least one store");
  if (fs::exists(out_dir / "points") ||
      (fs::exists(out_dir / "fits.json") && !fs::exists(out_dir / "fit_sources.txt")))
    throw ConfigError(fmt::format(
        "fit --out {}: that folder holds a sweep or a store, whose sweep.csv and fits.json this "
        "would replace; give a folder of its own",
        out_dir.string()));
  // Stores are named relative to the output folder, so that a committed fit names no path
  // outside the repository and still finds its points from anywhere.
  fs::create_directories(out_dir);
  const auto relative_name = [&](const fs::path& store) {
    return fs::relative(fs::weakly_canonical(store), fs::weakly_canonical(out_dir)).string();
  };
  Combination c;
  c.include_drifting = include_drifting;
  for (const auto& store : stores) c.add(store, relative_name(store));
  std::vector<std::string> columns = {"point", "status", "store"};
  columns.insert(columns.end(), c.summary_keys.begin(), c.summary_keys.end());

  json fits;
  fits["sweep"] = "combined";
  fits["includes_not_stationary"] = include_drifting;
  fits["stores"] = json::array();
  for (const auto& st : stores) fits["stores"].push_back(relative_name(st));
  fits["points"] = c.table.size();
  fits["finished"] = c.used;
  fits["seed_table1"] = seed_reference();
  fits["groups"] = json::array();
  if (!c.by_j.empty()) fits["groups"].push_back(fits_of_group(c.by_j, json::object()));
  std::string sources =
      "Fitted by `sheardiff fit` from (relative to this folder; each J from the first that holds "
      "it):\n";
  for (const auto& st : stores) sources += relative_name(st) + "\n";
  write_file_atomically(out_dir / "fit_sources.txt", sources);
  write_file_atomically(out_dir / "sweep.csv", csv_text(columns, c.table));
  write_file_atomically(out_dir / "fits.json", json_text(fits) + "\n");
  return fits;
}

}  // namespace sheardiff
