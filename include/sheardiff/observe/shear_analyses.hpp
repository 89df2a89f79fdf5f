#pragma once
// The analyses every sheared scene shares, composed by the scene's own observer list
// (src/scene/*.cpp).
#include <filesystem>
#include <memory>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/observe/observer.hpp"

namespace sheardiff {

// Over the measured window, as cfg asks for them: the profiles across the gap (a cell between
// walls, observables.profiles) and the diffusion analysis (analysis.diffusion, written to
// out_dir/analysis.h5).
template <class D>
void add_shear_analyses(ObserverListOf<D>& observers, const Config& cfg,
                        const std::filesystem::path& out_dir, MeasuredWindowOf<D> measuring,
                        bool between_walls);

}  // namespace sheardiff
