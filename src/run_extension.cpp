#include "sheardiff/run_extension.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include "sheardiff/config.hpp"
#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/io_error.hpp"
#include "sheardiff/io/run_directory.hpp"
#include "sheardiff/io/run_files.hpp"

namespace sheardiff {

namespace fs = std::filesystem;

namespace {

// The resolved configuration as "section.key" -> value text, from to_toml's lines.
std::map<std::string, std::string> config_entries(const std::string& toml_text) {
  std::map<std::string, std::string> out;
  std::istringstream in(toml_text);
  std::string line, section;
  while (std::getline(in, line)) {
    if (line.empty() || line.front() == '#') continue;
    if (line.front() == '[') {
      section = line.substr(1, line.find(']') - 1);
      continue;
    }
    const auto eq = line.find(" = ");
    if (eq != std::string::npos) out[section + "." + line.substr(0, eq)] = line.substr(eq + 3);
  }
  return out;
}

// A number as to_toml writes it; NaN for anything else (a missing key).
double number(const std::string& text) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    return used == text.size() ? v : std::nan("");
  } catch (const std::exception&) {
    return std::nan("");
  }
}

std::string file_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) throw IoError(fmt::format("cannot read {}", file.string()));
  if (!in.is_open()) throw IoError(fmt::format("cannot open {}", file.string()));
  return bytes;
}

void move_if_there(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  if (!fs::exists(from, ec)) return;
  fs::rename(from, to, ec);
  if (ec)
    throw IoError(
        fmt::format("cannot move {} to {}: {}", from.string(), to.string(), ec.message()));
}

}  // namespace

std::vector<ConfigChange> config_changes(const std::string& was, const std::string& now) {
  std::vector<ConfigChange> changes;
  if (was == now) return changes;
  const auto a = config_entries(was), b = config_entries(now);
  for (const auto& [key, value] : b) {
    const auto it = a.find(key);
    if (it == a.end())
      changes.push_back({key, "", value});
    else if (it->second != value)
      changes.push_back({key, it->second, value});
  }
  for (const auto& [key, value] : a)
    if (!b.count(key)) changes.push_back({key, value, ""});
  return changes;
}

std::string describe(const ConfigChange& c) {
  return fmt::format("{}: {} -> {}", c.key, c.was.empty() ? "not set" : c.was,
                     c.now.empty() ? "not set" : c.now);
}

std::string describe(const std::vector<ConfigChange>& changes) {
  std::string out;
  for (const auto& c : changes) out += (out.empty() ? "" : "; ") + describe(c);
  return out;
}

std::string changed_default_hint(const std::vector<ConfigChange>& changes) {
  const auto bare = [](const std::string& v) {  // a TOML string as --set takes it
    return v.size() >= 2 && v.front() == '"' && v.back() == '"' ? v.substr(1, v.size() - 2) : v;
  };
  for (const auto& c : changes)
    for (const auto& d : file_defaults())
      if (c.key == d.key && c.was == d.record_value && c.now == d.file_value)
        return fmt::format(
            ". A config file of {0} that does not name {1} runs {2}; a run an earlier sheardiff "
            "started from such a file ran {3}: name it (--set {1}={4}) to continue that run",
            d.scenes, d.key, d.file_value, d.record_value, bare(d.record_value));
  return "";
}

bool only_moves_the_end(const std::vector<ConfigChange>& changes) {
  if (changes.empty()) return false;
  for (const auto& c : changes) {
    const double was = number(c.was), now = number(c.now);
    if (!(was == was && now == now)) return false;  // not both numbers
    const bool further = (c.key == "run.strain" || c.key == "steady.measure_strain")
                             ? now > was
                             : c.key == "run.max_steps" && (now == 0.0 || (was > 0.0 && now > was));
    if (!further) return false;
  }
  return true;
}

bool only_moves_the_end(const std::string& was, const std::string& now) {
  try {
    return only_moves_the_end(config_changes(
        to_toml(parse_config(was, "checkpoint.bin", {}, ConfigSource::record)), now));
  } catch (const ConfigError&) {
    return false;
  }
}

fs::path set_aside_finished_results(RunDirectory& dir, double end_strain) {
  // The checkpoint first: from here on, whatever stops this, DIR can be resumed.
  write_file_atomically(dir.file(kCheckpointFile), file_bytes(dir.file(kFinalStateFile)));
  // A folder of its own: two ends may print alike ({:.6g}); one whose summary is not yet there
  // is this extension's own, begun by a command that was killed.
  fs::path to = dir.file(kEarlierFolder) / fmt::format("end_strain={:.6g}", end_strain);
  for (int k = 2; fs::exists(to / kSummaryFile); ++k)
    to = dir.file(kEarlierFolder) / fmt::format("end_strain={:.6g}_{}", end_strain, k);
  std::error_code ec;
  fs::create_directories(to, ec);
  if (ec) throw IoError(fmt::format("cannot make {}: {}", to.string(), ec.message()));
  if (fs::exists(dir.file(kConfigFile)))
    write_file_atomically(to / kConfigFile, file_bytes(dir.file(kConfigFile)));
  for (const char* name : kAnalyserFiles) move_if_there(dir.file(name), to / name);
  move_if_there(dir.file(kReanalysisFolder), to / kReanalysisFolder);
  // Last: without its summary DIR holds an interrupted run.
  move_if_there(dir.file(kSummaryFile), to / kSummaryFile);
  return to;
}

}  // namespace sheardiff
