#pragma once
// What `sheardiff run` and `sheardiff analyse` print about a finished run, from its summary.
#include <nlohmann/json.hpp>
#include <string>

namespace sheardiff {

// The result's first line (printed even with --quiet).
std::string run_result_first_line(const nlohmann::json& summary, const std::string& out_dir);
// The lines after it: steady state or stresses, diffusion.
std::string run_result_details(const nlohmann::json& summary);
// `analyse`: the diffusion results of the re-analysed run.
std::string analysis_result_text(const nlohmann::json& js, const std::string& run_dir);
// The analysis warnings of a summary, on stderr.
void print_warnings(const nlohmann::json& js);

}  // namespace sheardiff
