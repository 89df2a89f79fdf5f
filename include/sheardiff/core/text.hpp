#pragma once
// How sheardiff writes numbers, times and durations, in one place: the files it writes (TOML,
// JSON) and what it prints (progress lines, ETAs, config-doc) all go through these.
#include <chrono>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace sheardiff {

// A duration for people, one format everywhere: "27s", "3m13s", "1h02m"; "?" if unknown
// (negative, NaN or beyond three years).
std::string duration_text(double seconds);

// ISO 8601 in UTC to the second: "2025-03-01T14:07:09Z".
std::string iso8601_utc(std::chrono::system_clock::time_point t);
inline std::string iso8601_utc_now() {
  return iso8601_utc(std::chrono::system_clock::now());
}

// This machine's host name ("?" if it cannot be had).
std::string host_name();

// The shortest decimal text that reads back to the same double ("0.7", "1e-05"), written as a
// TOML float: "2.0", not "2"; "inf", "-inf", "nan".
std::string toml_float(double x);
// A TOML basic string, quoted and escaped ("a\"b\n" -> "\"a\\\"b\\n\"").
std::string toml_string(std::string_view s);

// nlohmann::json::dump(indent), with every float written as its shortest round-trip text
// (dump's Grisu2 writes a 17th digit for about one double in a thousand) and as a float ("2.0").
// Non-finite floats are null, as dump writes them.
std::string json_text(const nlohmann::json& js, int indent = 2);

// `text` wrapped at spaces into lines of at most `width` characters (UTF-8 code points), each
// line after `indent`; a single word longer than the room is left whole on its own line.
std::string wrap_text(std::string_view text, std::size_t width, std::string_view indent = "");

}  // namespace sheardiff
