#pragma once
// The files of a run directory, each named once. The run directory's ownership rules, the end of
// a run, the restart check and the results store read these lists, so an observer that writes a
// new file adds it here and nowhere else.
#include <array>

namespace sheardiff {

// What the analysers write when a run finishes (their tables; docs/outputs.md).
inline constexpr const char* kAnalysisFile = "analysis.h5";  // DiffusionObserver
inline constexpr const char* kChannelFile = "channel.h5";    // ChannelObserver
inline constexpr std::array<const char*, 2> kAnalyserFiles = {kAnalysisFile, kChannelFile};

// What a run writes besides them.
inline constexpr const char* kConfigFile = "config.toml";
inline constexpr const char* kTrajectoryFile = "trajectory.h5";
inline constexpr const char* kSummaryFile = "summary.json";
inline constexpr const char* kCheckpointFile = "checkpoint.bin";
inline constexpr const char* kDiagnosticFile = "diagnostic.txt";
inline constexpr const char* kReanalysisFolder = "reanalysis";
// A finished run's state at its end (a checkpoint), from which it can be extended.
inline constexpr const char* kFinalStateFile = "final_state.bin";
// Where an extension keeps what the run had written when it finished: earlier/end_strain=S/.
inline constexpr const char* kEarlierFolder = "earlier";

}  // namespace sheardiff
