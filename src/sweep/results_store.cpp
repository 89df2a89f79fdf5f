// The persistent record of a sweep: each finished point's small results (no trajectories) in
// spec.results/points/<name>/, so that a sweep spread over sessions, machines or a cluster is
// continued and re-fitted from these files alone (docs/sweeps.md, "Results that persist").
#include <fmt/format.h>

#include <fstream>
#include <sstream>

#include "sheardiff/config.hpp"
#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/run_files.hpp"
#include "sheardiff/run_extension.hpp"
#include "sheardiff/sweep/sweep.hpp"

namespace sheardiff {
namespace fs = std::filesystem;

namespace {

std::string read_all(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("cannot read {}", file.string()));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

fs::path stored_point(const SweepSpec& spec, const SweepPoint& p) {
  if (spec.results.empty()) return {};
  const auto dir = spec.results / "points" / p.name;
  if (!fs::exists(dir / "summary.json") || !fs::exists(dir / "config.toml")) return {};
  // The same point only if its configuration is this point's (compared through the parser, as
  // for run directories): a changed sweep never silently reuses old results.
  std::string theirs;
  try {
    theirs = to_toml(load_config(dir / "config.toml", {}, ConfigSource::record));
  } catch (const ConfigError&) {
    return {};
  }
  const std::string mine = to_toml(load_config(spec.base, p.overrides));
  if (theirs != mine) {
    const auto changes = config_changes(theirs, mine);
    throw ConfigError(fmt::format(
        "{} holds results of another configuration than sweep point {} ({}; sweep file or base "
        "config changed?); move them away or name another sweep.results{}",
        dir.string(), p.name, describe(changes), changed_default_hint(changes)));
  }
  return dir;
}

bool export_point(const SweepSpec& spec, const SweepPoint& p, const fs::path& out_dir) {
  if (spec.results.empty()) return false;
  const auto src = point_dir(out_dir, p);
  if (!fs::exists(src / "summary.json") || !fs::exists(src / "config.toml")) return false;
  const auto dst = spec.results / "points" / p.name;
  fs::create_directories(dst);
  bool copied = false;
  // config.toml first and summary.json last: a stored point counts once its summary is there.
  std::vector<const char*> names = {kConfigFile};
  names.insert(names.end(), kAnalyserFiles.begin(), kAnalyserFiles.end());
  names.push_back(kSummaryFile);
  for (const char* name : names) {
    if (!fs::exists(src / name)) continue;
    const std::string bytes = read_all(src / name);
    if (fs::exists(dst / name) && read_all(dst / name) == bytes) continue;
    write_file_atomically(dst / name, bytes);
    copied = true;
  }
  return copied;
}

}  // namespace sheardiff
