// Slurm backend: one job-array task per unfinished point, and a collect job after the array.
#include <fmt/format.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "sheardiff/config.hpp"
#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/sweep/sweep.hpp"

namespace sheardiff {
namespace fs = std::filesystem;

namespace {

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Runs a command, returns its stdout; throws with its output when it fails.
std::string run_command(const std::string& cmd) {
  FILE* pipe = popen((cmd + " 2>&1").c_str(), "r");
  if (!pipe) throw std::runtime_error(fmt::format("cannot run {}: {}", cmd, std::strerror(errno)));
  std::string out;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) out.append(buf.data(), n);
  const int status = pclose(pipe);
  if (status != 0) throw std::runtime_error(fmt::format("`{}` failed: {}", cmd, out));
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}

// sbatch reads #SBATCH lines only up to the first command: `extra` directives go in here.
std::string header(const SweepSpec& spec, const std::string& name, const fs::path& log,
                   const std::string& extra = "") {
  std::string h = "#!/bin/bash\n" + extra;
  h += fmt::format("#SBATCH --job-name={}\n", name);
  h += fmt::format("#SBATCH --output={}\n", log.string());
  h += fmt::format("#SBATCH --time={}\n", spec.slurm.time);
  h += fmt::format("#SBATCH --ntasks=1\n#SBATCH --cpus-per-task={}\n", spec.slurm.cpus_per_task);
  if (!spec.slurm.mem_per_task.empty())
    h += fmt::format("#SBATCH --mem={}\n", spec.slurm.mem_per_task);
  if (!spec.slurm.partition.empty())
    h += fmt::format("#SBATCH --partition={}\n", spec.slurm.partition);
  for (const auto& e : spec.slurm.extra) h += fmt::format("#SBATCH {}\n", e);
  // One thread per allocated CPU: CHOLMOD's OpenMP regions obey only OMP_THREAD_LIMIT.
  h += fmt::format("export OMP_THREAD_LIMIT={}\nset -euo pipefail\n", spec.slurm.cpus_per_task);
  return h;
}

}  // namespace

std::pair<std::string, std::string> submit_slurm(const SweepSpec& spec, const fs::path& out_dir,
                                                 const fs::path& exe) {
  const auto points = expand_points(spec);
  const fs::path out = fs::absolute(out_dir);
  fs::create_directories(out / "points");
  fs::create_directories(out / "logs");
  fs::create_directories(out / "slurm");
  std::vector<long> todo;
  for (const auto& p : points)
    if (point_state(spec, p, out) != PointState::finished) todo.push_back(p.index);

  const std::string call = fmt::format("{} sweep {} --out {}", shell_quote(exe.string()),
                                       shell_quote(spec.file.string()), shell_quote(out.string()));
  std::string array_id;
  if (!todo.empty()) {
    std::string array =
        header(spec, spec.slurm.job_name, out / "logs" / "slurm-%A_%a.out",
               fmt::format("#SBATCH --array={}{}\n", fmt::join(todo, ","),
                           spec.slurm.throttle > 0 ? fmt::format("%{}", spec.slurm.throttle) : ""));
    array += fmt::format("exec {} --point \"$SLURM_ARRAY_TASK_ID\"\n", call);
    write_file_atomically(out / "slurm" / "array.sbatch", array);
    array_id = run_command(fmt::format("sbatch --parsable {}",
                                       shell_quote((out / "slurm" / "array.sbatch").string())));
    array_id = array_id.substr(0, array_id.find(';'));  // "id;cluster" on federated clusters
  }
  std::string collect =
      header(spec, spec.slurm.job_name + "-collect", out / "logs" / "slurm-collect-%j.out");
  collect += fmt::format("exec {} --collect\n", call);
  write_file_atomically(out / "slurm" / "collect.sbatch", collect);
  // afterany: the fits are made from whatever finished, and a failed point is reported in
  // sweep.csv rather than silently holding the collection back.
  std::string collect_id = run_command(fmt::format(
      "sbatch --parsable {}{}", array_id.empty() ? "" : "--dependency=afterany:" + array_id + " ",
      shell_quote((out / "slurm" / "collect.sbatch").string())));
  collect_id = collect_id.substr(0, collect_id.find(';'));
  write_file_atomically(
      out / "slurm" / "jobs.json",
      nlohmann::json{{"array", array_id}, {"collect", collect_id}, {"points", todo}}.dump(2) +
          "\n");
  return {array_id, collect_id};
}

}  // namespace sheardiff
