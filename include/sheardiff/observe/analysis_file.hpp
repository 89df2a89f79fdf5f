#pragma once
// The diffusion analysis of a run as a file of its directory, written by the observer that
// accumulated it and by `sheardiff analyse`.
#include <filesystem>

#include "sheardiff/analysis/diffusion.hpp"

namespace sheardiff {

// DIR/analysis.h5: /msd/{lag, msd, samples}, /msd_coarse, /vacf/{lag, c}, fit results as
// attributes of / (docs/outputs.md). Complete or absent: written under a temporary name.
void write_analysis_file(const DiffusionReport& r, const std::filesystem::path& file);

}  // namespace sheardiff
