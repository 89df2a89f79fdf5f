#pragma once
// Run health (issue 6): cheap checks after every step that stop a run gone wrong (non-finite
// state, contacts overlapping far beyond what the spring model means, a failed or inaccurate
// linear solve, a top wall that escapes or collapses) instead of letting it finish with
// silently wrong numbers. The run then exits with kExitUnhealthy (docs/stability.md).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/integrator/dynamics.hpp"
#include "sheardiff/integrator/stress.hpp"

namespace sheardiff {

// Exit code of `sheardiff run` stopped by a health check.
inline constexpr int kExitUnhealthy = 4;

enum class HealthProblem { NonFinite, Overlap, SolverFailure, Residual, WallEscape, WallCollapse };
const char* to_string(HealthProblem p);

struct HealthReport {
  HealthProblem problem = HealthProblem::NonFinite;
  long step = 0;
  double strain = 0.0;
  std::vector<int> particles;  // the offending particles (may be empty)
  std::string what;            // what was detected, with values and particle ids
  std::string advice;          // which config keys to change
  bool state_finite = true;    // positions and velocities finite: a checkpoint can be written
  std::string message() const;
};

// Thrown by run_to_directory after the checkpoint and the diagnostic frame are written.
struct RunUnhealthy : std::runtime_error {
  explicit RunUnhealthy(HealthReport r) : std::runtime_error(r.message()), report(std::move(r)) {}
  HealthReport report;
};

template <class D>
class RunHealthOf {
 public:
  using Dynamics = DynamicsOf<D>;
  using Velocities = VelocitiesOf<D>;

  // Records the reference state (initial gap of a wall scene); build it on the initial state.
  RunHealthOf(const Config& cfg, const Dynamics& d);

  // After a completed step with velocities v: the first problem found, if any.
  std::optional<HealthReport> check(const Dynamics& d, const Velocities& v, double dt);
  // The integrator's linear solve failed at the current (unchanged) state.
  HealthReport solver_failure(const Dynamics& d, const Velocities& v) const;

  // Largest overlap at the current positions over the listed pairs; *pair = its index.
  static double max_overlap(const Dynamics& d, std::size_t* pair = nullptr);

  // Largest values seen (summary.json "health").
  void report(nlohmann::json& summary) const;
  void serialize(Archive& a) {
    a.tag("health");
    a.io(h0_), a.io(max_overlap_seen_), a.io(max_residual_seen_);
  }

 private:
  HealthReport make(HealthProblem p, const Dynamics& d, std::vector<int> ids,
                    std::string what) const;

  double max_overlap_, max_residual_;
  bool explicit_springs_, fixed_dt_;
  double h0_ = 0.0;              // initial wall gap (wall scenes)
  double mobile_measure_ = 0.0;  // area of the mobile discs, volume of the mobile spheres
  double max_overlap_seen_ = 0.0, max_residual_seen_ = 0.0;
};

using RunHealth = RunHealthOf<Dim2>;

// A text frame of every particle (id, position, diameter, velocity, motion, flagged) headed
// by the report, for post-mortems of a stopped run.
template <class D>
void write_diagnostic(const std::filesystem::path& file, const DynamicsOf<D>& d,
                      const VelocitiesOf<D>& v, const HealthReport& r);

}  // namespace sheardiff
