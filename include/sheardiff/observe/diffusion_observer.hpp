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

// Samples the mobile discs every analysis.sample_strain of the measured window (the unwrapped
// y, v_y / gammadot, the x displacement relative to the imposed flow and, with walls, whether
// each disc is in the bulk) into a DiffusionAccumulator, and analyses them at the end of the
// run. Nothing grows with the window: the checkpoint carries the accumulator. With
// analysis.sample_strain = output.frame_strain the samples are the trajectory's frames, and
// `sheardiff analyse DIR` recomputes the same numbers from them.
template <class D>
class DiffusionObserverOf final : public ObserverOf<D> {
 public:
  using typename ObserverOf<D>::Dynamics;
  using typename ObserverOf<D>::StepView;

  // measuring(d): whether the run is in the measured window.
  DiffusionObserverOf(const Config& cfg, std::filesystem::path analysis_file,
                      MeasuredWindowOf<D> measuring);
  void on_step(const StepView& v) override;
  void on_frame(const StepView& v, std::vector<double>& values) override;
  void finish(const Dynamics& d, nlohmann::json& summary, H5mdWriter* writer) override;
  void serialize(Archive& a) override;

 private:
  void take_sample(const StepView& v);

  DiffusionSettings settings_;
  double sample_strain_;
  double next_sample_;
  std::filesystem::path file_;
  MeasuredWindowOf<D> measuring_;
  double exclusion_;
  long particles_ = 0;     // 0 until the first sample
  bool walls_ = false;     // samples carry a bulk mask
  long skipped_ = 0;       // sample marks that fell inside one step with another
  long due_at_step_ = -1;  // a sample was due at this step before the window opened
  std::vector<double> x_;  // x displacement relative to the imposed flow since the first sample
  DiffusionAccumulator acc_;
  std::vector<double> y_, vy_;
  std::vector<std::uint8_t> bulk_;
};

using DiffusionObserver = DiffusionObserverOf<Dim2>;

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
