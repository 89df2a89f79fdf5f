// The sweep file, its points and the state of each point's run directory.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "sheardiff/config.hpp"
#include "sheardiff/run.hpp"
#include "sheardiff/run_extension.hpp"
#include "sheardiff/sweep/sweep.hpp"

namespace sheardiff {
namespace fs = std::filesystem;

namespace {

// A TOML value as the text --set would take: numbers in their shortest round-trip form.
std::string value_text(const toml::node& v, const std::string& where) {
  if (auto i = v.as_integer()) return fmt::format("{}", i->get());
  if (auto d = v.as_floating_point()) return fmt::format("{}", d->get());
  if (auto b = v.as_boolean()) return b->get() ? "true" : "false";
  if (auto s = v.as_string()) return fmt::format("\"{}\"", s->get());
  // A list key (analysis.velocity_intervals): its numbers, as --set reads a TOML array.
  if (auto a = v.as_array()) {
    std::string out = "[";
    for (std::size_t i = 0; i < a->size(); ++i) {
      const toml::node& x = *a->get(i);
      if (!x.is_number()) throw ConfigError(fmt::format("{}: a list may only hold numbers", where));
      out += (i ? ", " : "") + value_text(x, where);
    }
    return out + "]";
  }
  throw ConfigError(
      fmt::format("{}: must be a number, a boolean, a string or a list of numbers", where));
}

// The value as it appears in a directory name: no quotes, nothing a path cannot hold.
std::string name_text(std::string v) {
  if (v.size() >= 2 && v.front() == '"') v = v.substr(1, v.size() - 2);
  for (char& c : v)
    if (c == '/' || c == ' ' || c == '=' || c == '_') c = '-';
  return v;
}

void reject_unknown(const toml::table& t, const std::set<std::string>& known,
                    const std::string& where) {
  for (const auto& [k, v] : t) {
    (void)v;
    if (!known.count(std::string(k.str())))
      throw ConfigError(fmt::format("{}: unknown key '{}' (allowed: {})", where, k.str(),
                                    fmt::join(known, ", ")));
  }
}

template <class T>
T get_or(const toml::table& t, const char* key, T fallback, const std::string& where) {
  const auto* n = t.get(key);
  if (!n) return fallback;
  if (auto v = n->value<T>()) return *v;
  throw ConfigError(fmt::format("{}.{}: wrong type", where, key));
}

Config point_config(const SweepSpec& spec, const SweepPoint& p) {
  return load_config(spec.base, p.overrides);
}

}  // namespace

bool is_sweep_file(const fs::path& file) {
  try {
    const toml::table root = toml::parse_file(file.string());
    return root.contains("sweep");
  } catch (const toml::parse_error&) {
    return false;  // the config loader reports the syntax error with its position
  }
}

namespace {

// [sweep] base, results, jobs and backend, paths relative to the sweep file.
void read_where_and_how(const toml::table& sweep, const std::string& w, SweepSpec& spec) {
  const auto base = get_or<std::string>(sweep, "base", "", w);
  if (base.empty()) throw ConfigError(fmt::format("{}.base: missing (the base config file)", w));
  spec.base = fs::path(base).is_absolute() ? fs::path(base) : spec.file.parent_path() / base;
  spec.base = spec.base.lexically_normal();
  if (!fs::exists(spec.base))
    throw ConfigError(
        fmt::format("{}.base = \"{}\": no such file ({})", w, base, spec.base.string()));
  if (!fs::is_regular_file(spec.base))
    throw ConfigError(
        fmt::format("{}.base = \"{}\": {} is {}, not a config file", w, base, spec.base.string(),
                    fs::is_directory(spec.base) ? "a directory" : "not a regular file"));

  if (const auto results = get_or<std::string>(sweep, "results", "", w); !results.empty())
    spec.results =
        (fs::path(results).is_absolute() ? fs::path(results) : spec.file.parent_path() / results)
            .lexically_normal();

  spec.jobs = static_cast<int>(get_or<int64_t>(sweep, "jobs", 2, w));
  if (spec.jobs < 1 || spec.jobs > 256)
    throw ConfigError(fmt::format("{}.jobs = {}: must be in [1, 256]", w, spec.jobs));
  spec.backend = get_or<std::string>(sweep, "backend", "local", w);
  if (spec.backend != "local" && spec.backend != "slurm")
    throw ConfigError(
        fmt::format("{}.backend = \"{}\": must be \"local\" or \"slurm\"", w, spec.backend));
}

// [sweep.axes] in the order the file gives them, and [sweep.set].
void read_set_and_axes(const toml::table& sweep, const std::string& w, SweepSpec& spec) {
  if (const auto* set = sweep["set"].as_table())
    for (const auto& [k, v] : *set)
      spec.set.emplace_back(std::string(k.str()),
                            value_text(v, fmt::format("{}.set.\"{}\"", w, k.str())));
  const auto* axes = sweep["axes"].as_table();
  if (!axes || axes->empty())
    throw ConfigError(
        fmt::format("{}.axes: missing; give at least one axis, e.g. "
                    "\"flow.J\" = [1e-1, 1e-2]",
                    w));
  // Axes in the order the file gives them (toml++ iterates keys sorted): it fixes the point
  // names and numbering.
  std::vector<std::pair<std::string, const toml::node*>> ordered;
  for (const auto& [k, v] : *axes) ordered.emplace_back(std::string(k.str()), &v);
  std::stable_sort(ordered.begin(), ordered.end(), [](const auto& a, const auto& b) {
    const auto& sa = a.second->source().begin;
    const auto& sb = b.second->source().begin;
    return sa.line != sb.line ? sa.line < sb.line : sa.column < sb.column;
  });
  for (const auto& [k, node] : ordered) {
    const toml::node& v = *node;
    const std::string where = fmt::format("{}.axes.\"{}\"", w, k);
    const auto* arr = v.as_array();
    if (!arr || arr->empty())
      throw ConfigError(fmt::format("{}: must be a non-empty list of values", where));
    std::vector<std::string> values;
    for (const auto& e : *arr) values.push_back(value_text(e, where));
    // Two equal values (0.1 and 1e-1, or names that differ only in '_' and '-') would run one
    // point twice, racing in one directory, and count it twice in sweep.csv and fits.json.
    for (std::size_t i = 0; i < values.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (name_text(values[i]) == name_text(values[j]))
          throw ConfigError(fmt::format(
              "{}: entries {} and {} of the list are the same value ({}{}): a point would run "
              "twice in one directory and count twice; remove one",
              where, j + 1, i + 1, values[j],
              values[i] == values[j] ? "" : " and " + values[i] + ", one directory name"));
    spec.axes.emplace_back(k, std::move(values));
  }
  // A key given both as a fixed value and as an axis has no single meaning: refuse it rather
  // than let one silently win.
  for (const auto& [k, v] : spec.set) {
    (void)v;
    for (const auto& axis : spec.axes)
      if (axis.first == k)
        throw ConfigError(fmt::format(
            "{}.set.\"{}\": also an axis ({}.axes.\"{}\"); give it in one place", w, k, w, k));
  }
}

// [sweep.paired."AXIS"]: keys that take one value per entry of an axis.
void read_paired(const toml::node& node, const std::string& w, SweepSpec& spec) {
  const auto* paired = node.as_table();
  if (!paired)
    throw ConfigError(
        fmt::format("{}.paired: must be a table of axes, e.g. [sweep.paired.\"flow.J\"] "
                    "\"particles.phi_init\" = [0.74, 0.62]",
                    w));
  std::set<std::string> taken;
  for (const auto& [ak, an] : *paired) {
    const std::string axis_key(ak.str());
    const std::string where = fmt::format("{}.paired.\"{}\"", w, axis_key);
    const auto axis = std::find_if(spec.axes.begin(), spec.axes.end(),
                                   [&](const auto& a) { return a.first == axis_key; });
    if (axis == spec.axes.end())
      throw ConfigError(fmt::format("{}: \"{}\" is not an axis of {}.axes", where, axis_key, w));
    const auto* keys = an.as_table();
    if (!keys || keys->empty())
      throw ConfigError(fmt::format(
          "{}: must be a table of keys, each a list of one value per entry of the axis", where));
    for (const auto& [kk, kv] : *keys) {
      const std::string key(kk.str());
      const std::string wk = fmt::format("{}.\"{}\"", where, key);
      const auto* arr = kv.as_array();
      if (!arr || arr->size() != axis->second.size())
        throw ConfigError(fmt::format("{}: must be a list of {} values, one per entry of the axis",
                                      wk, axis->second.size()));
      const bool in_axes = std::any_of(spec.axes.begin(), spec.axes.end(),
                                       [&](const auto& a) { return a.first == key; });
      const bool in_set = std::any_of(spec.set.begin(), spec.set.end(),
                                      [&](const auto& s) { return s.first == key; });
      if (in_axes || in_set || !taken.insert(key).second)
        throw ConfigError(fmt::format("{}: the key is also {}; give it in one place", wk,
                                      in_axes  ? "an axis"
                                      : in_set ? "in [sweep.set]"
                                               : "paired with another axis"));
      std::vector<std::string> values;
      for (const auto& e : *arr) values.push_back(value_text(e, wk));
      spec.paired.push_back(
          {static_cast<std::size_t>(axis - spec.axes.begin()), key, std::move(values)});
    }
  }
}

// [slurm]: how the Slurm backend submits the points.
void read_slurm(const toml::table& s, const std::string& origin, SweepSpec& spec) {
  const std::string ws = origin + ": slurm";
  reject_unknown(
      s, {"throttle", "time", "partition", "job_name", "cpus_per_task", "mem_per_task", "extra"},
      ws);
  spec.slurm.throttle = static_cast<int>(get_or<int64_t>(s, "throttle", 0, ws));
  if (spec.slurm.throttle < 0)
    throw ConfigError(
        fmt::format("{}.throttle = {}: must be >= 0 (0 = no limit)", ws, spec.slurm.throttle));
  spec.slurm.time = get_or<std::string>(s, "time", spec.slurm.time, ws);
  spec.slurm.partition = get_or<std::string>(s, "partition", "", ws);
  spec.slurm.job_name = get_or<std::string>(s, "job_name", spec.slurm.job_name, ws);
  spec.slurm.cpus_per_task = static_cast<int>(get_or<int64_t>(s, "cpus_per_task", 1, ws));
  if (spec.slurm.cpus_per_task < 1)
    throw ConfigError(
        fmt::format("{}.cpus_per_task = {}: must be >= 1", ws, spec.slurm.cpus_per_task));
  spec.slurm.mem_per_task = get_or<std::string>(s, "mem_per_task", spec.slurm.mem_per_task, ws);
  if (const auto* extra = s["extra"].as_array())
    for (const auto& e : *extra) {
      auto str = e.value<std::string>();
      if (!str) throw ConfigError(fmt::format("{}.extra: must be a list of strings", ws));
      spec.slurm.extra.push_back(*str);
    }
}

// Every point must be a valid run, and a run of its own, before any of them starts.
void check_points(const SweepSpec& spec, const std::string& origin) {
  std::map<std::string, std::string> point_of_config;
  for (const auto& p : expand_points(spec)) {
    Config cfg;
    try {
      cfg = point_config(spec, p);
      validate_run_inputs(cfg, spec.base.string());
    } catch (const ConfigError& e) {
      throw ConfigError(fmt::format("{}: point {}: {}", origin, p.name, e.what()));
    }
    const auto [it, fresh] = point_of_config.emplace(to_toml(cfg), p.name);
    if (!fresh)
      throw ConfigError(fmt::format(
          "{}: points {} and {} run the same configuration (an axis value that changes nothing "
          "once resolved): it would be computed twice and count twice in sweep.csv and "
          "fits.json; remove one",
          origin, it->second, p.name));
  }
}

}  // namespace

SweepSpec load_sweep(const fs::path& file) {
  SweepSpec spec;
  spec.file = fs::absolute(file);
  const std::string origin = file.string();
  toml::table root;
  try {
    root = toml::parse_file(spec.file.string());
  } catch (const toml::parse_error& e) {
    throw ConfigError(fmt::format("{}: not valid TOML: {} (line {})", origin, e.description(),
                                  e.source().begin.line));
  }
  reject_unknown(root, {"sweep", "slurm"}, origin);
  const auto* sweep = root["sweep"].as_table();
  if (!sweep) throw ConfigError(fmt::format("{}: missing the [sweep] table", origin));
  const std::string w = origin + ": sweep";
  reject_unknown(*sweep, {"base", "jobs", "backend", "set", "axes", "paired", "results"}, w);
  read_where_and_how(*sweep, w, spec);
  read_set_and_axes(*sweep, w, spec);
  if (const auto* node = sweep->get("paired")) read_paired(*node, w, spec);
  if (const auto* s = root["slurm"].as_table()) read_slurm(*s, origin, spec);
  check_points(spec, origin);
  return spec;
}

std::vector<SweepPoint> expand_points(const SweepSpec& spec) {
  std::vector<SweepPoint> points;
  size_t total = 1;
  for (const auto& axis : spec.axes) total *= axis.second.size();
  for (size_t index = 0; index < total; ++index) {
    SweepPoint p;
    p.index = static_cast<long>(index);
    for (const auto& [k, v] : spec.set) p.overrides.push_back(k + "=" + v);
    // Mixed-radix digits of the index, the last axis fastest.
    std::vector<size_t> at(spec.axes.size());
    for (size_t a = spec.axes.size(), rest = index; a-- > 0;) {
      at[a] = rest % spec.axes[a].second.size();
      rest /= spec.axes[a].second.size();
    }
    std::vector<std::string> parts;
    for (size_t a = 0; a < spec.axes.size(); ++a) {
      const auto& [key, values] = spec.axes[a];
      p.overrides.push_back(key + "=" + values[at[a]]);
      parts.push_back(key.substr(key.rfind('.') + 1) + "=" + name_text(values[at[a]]));
    }
    for (const auto& pk : spec.paired) p.overrides.push_back(pk.key + "=" + pk.values[at[pk.axis]]);
    p.name = fmt::format("{}", fmt::join(parts, "_"));
    points.push_back(std::move(p));
  }
  // Relative cost, for the ETA and to start the longest points first: the step costs ~N, the
  // steps per strain grow as J falls (J^-1/2 here, a bound: 4.75x from J = 1e-2 to 1e-4 at
  // N = 1000, docs/performance.md), and the strain run.
  for (auto& p : points) {
    Config cfg;
    try {
      cfg = point_config(spec, p);
    } catch (const ConfigError&) {
      continue;  // load_sweep reports it, with the point's name
    }
    const double strain =
        scene_kind(cfg.scene.type).measured_from_steady_state() && cfg.steady.measure_strain > 0
            ? cfg.steady.measure_strain + 3.0 * cfg.steady.window
            : cfg.run.strain;
    p.cost = static_cast<double>(cfg.particles.n) * std::max(strain, 1e-3) /
             std::sqrt(std::max(cfg.flow.j, 1e-8));
  }
  return points;
}

fs::path point_dir(const fs::path& out_dir, const SweepPoint& p) {
  return out_dir / "points" / p.name;
}

PointState point_state(const SweepSpec& spec, const SweepPoint& p, const fs::path& out_dir) {
  const auto dir = point_dir(out_dir, p);
  // Finished on another machine or in an earlier session: its results are stored.
  if (!fs::exists(dir / "summary.json") && !stored_point(spec, p).empty())
    return PointState::finished;
  if (!fs::exists(dir / "config.toml")) return PointState::fresh;
  // Compared through the parser, so keys added to the code since the point ran (defaults) do
  // not make a finished point look foreign.
  std::string mine = to_toml(point_config(spec, p)), theirs;
  try {
    theirs = to_toml(load_config(dir / "config.toml", {}, ConfigSource::record));
  } catch (const ConfigError&) {
  }
  if (mine != theirs) {
    if (!fs::exists(dir / "summary.json") && !fs::exists(dir / "checkpoint.bin"))
      return PointState::fresh;  // an unfinished start with nothing to keep: redo it
    const auto changes =
        theirs.empty() ? std::vector<ConfigChange>{} : config_changes(theirs, mine);
    throw ConfigError(fmt::format(
        "{} holds a run of another configuration than sweep point {} ({}; sweep file or base "
        "config changed?); move it away or sweep into another --out{}",
        dir.string(), p.name, theirs.empty() ? "its config.toml does not parse" : describe(changes),
        changed_default_hint(changes)));
  }
  if (fs::exists(dir / "summary.json")) return PointState::finished;
  if (fs::exists(dir / "checkpoint.bin")) return PointState::resumable;
  return PointState::fresh;
}

}  // namespace sheardiff
