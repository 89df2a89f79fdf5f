#pragma once
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "sheardiff/analysis/diffusion.hpp"
#include "sheardiff/config.hpp"
#include "sheardiff/observe/observer.hpp"

namespace sheardiff {

DiffusionSettings diffusion_settings(const Config& cfg);

// Keeps, for every frame of the measured window, the unwrapped y and v_y / gammadot of the
// mobile particles, and analyses them at the end of the run (analyse_diffusion). The frames are
// exactly those written to the trajectory, so `sheardiff analyse DIR` recomputes the same numbers.
class DiffusionObserver final : public Observer {
 public:
  // measuring(d): whether the frame belongs to the measured window.
  DiffusionObserver(const Config& cfg, std::filesystem::path analysis_file,
                    std::function<bool(const Dynamics&)> measuring);
  void on_frame(const StepView& v, std::vector<double>& values) override;
  void finish(const Dynamics& d, nlohmann::json& summary, H5mdWriter* writer) override;
  void serialize(Archive& a) override {
    a.tag("diffusion");
    a.io(y_), a.io(vy_), a.io(frames_), a.io(bottom_), a.io(top_);
  }

 private:
  DiffusionSettings settings_;
  double frame_strain_;
  std::filesystem::path file_;
  std::function<bool(const Dynamics&)> measuring_;
  std::vector<double> y_, vy_;
  long frames_ = 0;
  double exclusion_;
  std::vector<double> bottom_, top_;  // wall centre lines per frame (scenes with walls)
};

// What `sheardiff analyse DIR` found: the run's summary with every recomputed key, and where it
// went. Keys the run lacked (a run without the diffusion analysis, an older version's) are
// added to DIR/summary.json, and analysis.h5 is written if the run has none. If a key the run
// has comes out different, nothing of the run's is touched: the summary and analysis.h5 go to
// DIR/reanalysis/ and `differs` names those keys.
struct Reanalysis {
  nlohmann::json summary;
  std::vector<std::string> differs;
  std::filesystem::path folder;  // DIR, or DIR/reanalysis when `differs` is not empty
};

// Recomputes the analysis of a finished run from DIR/trajectory.h5, DIR/config.toml and
// DIR/summary.json alone. `overrides` (analysis.KEY=value, observables.KEY=value) analyse the
// same frames with other settings: that result always goes to DIR/reanalysis/, with the
// overrides in its summary (`analysed_with`). Another key is refused (ConfigError).
Reanalysis reanalyse_run(const std::filesystem::path& dir,
                         const std::vector<std::string>& overrides = {});

}  // namespace sheardiff
