#include "sheardiff/observe/shear_analyses.hpp"

#include "sheardiff/io/run_files.hpp"
#include "sheardiff/observe/diffusion_observer.hpp"
#include "sheardiff/observe/profiles.hpp"

namespace sheardiff {

void add_shear_analyses(ObserverList& observers, const Config& cfg,
                        const std::filesystem::path& out_dir, MeasuredWindow measuring,
                        bool between_walls) {
  if (cfg.observables.profiles && between_walls)
    observers.push_back(std::make_unique<ProfilesObserver>(cfg, measuring));
  if (cfg.analysis.diffusion)
    observers.push_back(
        std::make_unique<DiffusionObserver>(cfg, out_dir / kAnalysisFile, std::move(measuring)));
}

}  // namespace sheardiff
