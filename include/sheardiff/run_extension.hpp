#pragma once
// Continuing a run to a larger strain (`sheardiff run CONFIG --resume DIR --set run.strain=...`):
// which configuration changes only move the run's end, and how a finished run's results are set
// aside so that nothing of them is lost when the run goes on.
#include <filesystem>
#include <string>
#include <vector>

namespace sheardiff {

class RunDirectory;

// One key of a resolved configuration that differs: "section.key", its text before and now
// ("" when not set).
struct ConfigChange {
  std::string key, was, now;
};

// How the resolved configuration `now` differs from `was` (both as to_toml writes them), key by
// key; empty when they are the same.
std::vector<ConfigChange> config_changes(const std::string& was, const std::string& now);
// "key: was -> now" for messages.
std::string describe(const ConfigChange& c);
// Every change described, joined by "; ".
std::string describe(const std::vector<ConfigChange>& changes);
// For a refusal over these changes: how to keep a run's value of a key whose default changed
// under existing runs (a change from a file_defaults() entry's record value to its file value),
// starting with ". "; "" when no such key changed.
std::string changed_default_hint(const std::vector<ConfigChange>& changes);

// Whether every change moves the run's end further and nothing else: run.strain or
// steady.measure_strain larger, run.max_steps larger or 0 (no cap). A run continued under such
// a configuration is the run it would have been with that configuration from the start (the
// end is only tested, never anticipated, by the step loop and the observers).
bool only_moves_the_end(const std::vector<ConfigChange>& changes);
// The same for two resolved configuration texts (a checkpoint's and this run's); false if
// `was` no longer parses.
bool only_moves_the_end(const std::string& was, const std::string& now);

// Opens a finished run for its extension, each step safe to be killed after (docs/outputs.md,
// "Extending a run"): DIR/final_state.bin is copied to DIR/checkpoint.bin, then config.toml is
// copied and the analysers' files, reanalysis/ and last summary.json are moved to
// DIR/earlier/end_strain=S/ (S: the strain the run ended at). From then DIR holds an
// interrupted run, which the extension continues. Returns that folder.
std::filesystem::path set_aside_finished_results(RunDirectory& dir, double end_strain);

}  // namespace sheardiff
