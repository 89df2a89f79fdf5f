#include "sheardiff/observe/shear_analyses.hpp"

#include "sheardiff/io/run_files.hpp"
#include "sheardiff/observe/diffusion_observer.hpp"
#include "sheardiff/observe/profiles.hpp"

namespace sheardiff {

template <class D>
void add_shear_analyses(ObserverListOf<D>& observers, const Config& cfg,
                        const std::filesystem::path& out_dir, MeasuredWindowOf<D> measuring,
                        bool between_walls) {
  if (cfg.observables.profiles && between_walls)
    observers.push_back(std::make_unique<ProfilesObserverOf<D>>(cfg, measuring));
  if (cfg.analysis.diffusion)
    observers.push_back(std::make_unique<DiffusionObserverOf<D>>(cfg, out_dir / kAnalysisFile,
                                                                 std::move(measuring)));
}

template void add_shear_analyses(ObserverListOf<Dim2>&, const Config&, const std::filesystem::path&,
                                 MeasuredWindowOf<Dim2>, bool);
template void add_shear_analyses(ObserverListOf<Dim3>&, const Config&, const std::filesystem::path&,
                                 MeasuredWindowOf<Dim3>, bool);

}  // namespace sheardiff
