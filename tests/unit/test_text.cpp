// Issue 17 (command line): how sheardiff writes numbers, times and durations. Floats in TOML and
// JSON are the shortest text that reads back to the same double (config.toml had
// 0.69999999999999996 for phi_init = 0.7, toml++'s 17 digits); one duration format ("27s",
// "3m13s", "1h02m") for `run` (which printed "27 s") and `sweep`; ISO 8601 UTC timestamps.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <toml++/toml.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/core/text.hpp"
#include "sheardiff/version.hpp"

namespace sheardiff {
namespace {

// Parses "v = TEXT" with toml++ and returns v's double.
double toml_read(const std::string& text) {
  const toml::table t = toml::parse("v = " + text);
  const auto* node = t.get("v");
  EXPECT_TRUE(node != nullptr && node->is_floating_point()) << text;
  return node ? node->value<double>().value_or(NAN) : NAN;
}

// Whether the decimal text t of x is the shortest that reads back to x: rounded to one
// significant digit fewer, it reads back to another double.
bool is_shortest(const std::string& t, double x) {
  std::string digits;  // significant digits: no leading zeros, no trailing ones (".0" of "2.0")
  for (char c : t.substr(0, t.find_first_of("eE")))
    if (c >= '0' && c <= '9' && !(c == '0' && digits.empty())) digits += c;
  while (!digits.empty() && digits.back() == '0') digits.pop_back();
  if (digits.size() <= 1) return true;
  const std::string fewer = fmt::format("{:.{}e}", x, digits.size() - 2);
  return std::strtod(fewer.c_str(), nullptr) != x;
}

TEST(Text, DurationHasOneFormat) {
  EXPECT_EQ(duration_text(0.0), "0s");
  EXPECT_EQ(duration_text(27.4), "27s");
  EXPECT_EQ(duration_text(59.6), "1m00s");
  EXPECT_EQ(duration_text(193.0), "3m13s");
  EXPECT_EQ(duration_text(3599.0), "59m59s");
  EXPECT_EQ(duration_text(3600.0 + 2 * 60 + 10), "1h02m");
  EXPECT_EQ(duration_text(50 * 3600.0), "50h00m");
  EXPECT_EQ(duration_text(-1.0), "?");
  EXPECT_EQ(duration_text(NAN), "?");
  EXPECT_EQ(duration_text(1e12), "?");
}

TEST(Text, Iso8601Utc) {
  using namespace std::chrono;
  EXPECT_EQ(iso8601_utc(system_clock::time_point(seconds(0))), "1970-01-01T00:00:00Z");
  EXPECT_EQ(iso8601_utc(system_clock::time_point(seconds(1700000000) + milliseconds(999))),
            "2023-11-14T22:13:20Z");
  EXPECT_TRUE(
      std::regex_match(iso8601_utc_now(), std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)")));
}

TEST(Text, VersionLineNamesTheCommit) {
  EXPECT_TRUE(std::regex_match(
      version_line(),
      std::regex(R"(sheardiff \d+\.\d+\.\d+ \(git ([0-9a-f]{4,40}(-dirty)?|unknown)\))")))
      << version_line();
}

TEST(Text, TomlFloatIsShortestAndReadsBackBitIdentical) {
  EXPECT_EQ(toml_float(0.7), "0.7");
  EXPECT_EQ(toml_float(1.4), "1.4");
  EXPECT_EQ(toml_float(0.1 + 0.2), "0.30000000000000004");
  EXPECT_EQ(toml_float(2.0), "2.0");
  EXPECT_EQ(toml_float(-0.0), "-0.0");
  EXPECT_EQ(toml_float(1e-5), "1e-05");
  EXPECT_EQ(toml_float(1e300), "1e+300");
  EXPECT_EQ(toml_float(std::numeric_limits<double>::infinity()), "inf");
  // Random bit patterns (every exponent, subnormals) and random values of every magnitude.
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int k = 0; k < 100000; ++k) {
    double x = std::bit_cast<double>(rng());
    if (k % 2) x = unit(rng) * std::pow(10.0, static_cast<int>(rng() % 40) - 20);
    if (!std::isfinite(x)) continue;
    const std::string t = toml_float(x);
    const double back = toml_read(t);
    ASSERT_EQ(std::bit_cast<std::uint64_t>(back), std::bit_cast<std::uint64_t>(x)) << t;
    // Shortest: one digit fewer does not read back (fmt's Dragonbox, checked on a sample).
    if (k % 97 == 0) {
      EXPECT_TRUE(is_shortest(t, x)) << t;
    }
  }
}

TEST(Text, TomlStringReadsBack) {
  for (const std::string& s : std::vector<std::string>{
           "", "plain", "runs/start frame.h5", "quote \" and \\ backslash",
           "line\nbreak\ttab\r\b\f", std::string("ctrl\x01\x1f\x7f", 8), "unicode: phi \xcf\x86"}) {
    const toml::table t = toml::parse("v = " + toml_string(s));
    EXPECT_EQ(t["v"].value<std::string>().value_or("<none>"), s) << toml_string(s);
  }
}

TEST(Text, JsonTextIsDumpWithShortestFloats) {
  nlohmann::json js = {{"name", "a \"run\"\n"},
                       {"N", 500},
                       {"neg", -3},
                       {"big", std::uint64_t{1} << 63},
                       {"ok", true},
                       {"none", nullptr},
                       {"empty_object", nlohmann::json::object()},
                       {"empty_array", nlohmann::json::array()},
                       {"nested", {{"list", {1, 2, "three", {{"x", false}}}}}}};
  // Without floats, the text is nlohmann's, with and without indentation.
  EXPECT_EQ(json_text(js), js.dump(2));
  EXPECT_EQ(json_text(js, 4), js.dump(4));
  EXPECT_EQ(json_text(js, -1), js.dump());
  // Floats: the shortest round-trip text where dump writes a 17th digit.
  EXPECT_EQ(nlohmann::json(0.39905357921110157).dump(), "0.39905357921110157");
  EXPECT_EQ(json_text(nlohmann::json(0.39905357921110157)), "0.3990535792111016");
  EXPECT_EQ(json_text(nlohmann::json(2.0)), "2.0");
  EXPECT_EQ(json_text(nlohmann::json(NAN)), "null");
  std::mt19937_64 rng(16);
  nlohmann::json values = nlohmann::json::array();
  for (int k = 0; k < 20000; ++k) {
    const double x = std::bit_cast<double>(rng());
    if (std::isfinite(x)) values.push_back(x);
  }
  const std::string text = json_text({{"values", values}});
  const nlohmann::json back = nlohmann::json::parse(text);
  ASSERT_EQ(back["values"].size(), values.size());
  for (std::size_t k = 0; k < values.size(); ++k) {
    const double x = values[k].get<double>();
    ASSERT_EQ(std::bit_cast<std::uint64_t>(back["values"][k].get<double>()),
              std::bit_cast<std::uint64_t>(x));
    ASSERT_NE(text.find(fmt::format("{}", x)), std::string::npos) << x;
  }
}

TEST(Text, WrapKeepsLinesWithinTheWidth) {
  const std::string text =
      "Scene: `simple_shear` = Lees-Edwards periodic cell at fixed area fraction and shear rate; "
      "phi \xcf\x86 counts as one column. A_word_longer_than_the_whole_width_stays_whole_on_a_line";
  const std::string out = wrap_text(text, 30, "# ");
  std::istringstream lines(out);
  std::string words;
  for (std::string line; std::getline(lines, line);) {
    ASSERT_EQ(line.rfind("# ", 0), 0u) << line;
    std::size_t columns = 0;
    for (char c : line) columns += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
    if (line.find("A_word") == std::string::npos) {
      EXPECT_LE(columns, 30u) << line;
    }
    words += line.substr(2) + " ";
  }
  words.pop_back();
  EXPECT_EQ(words, text) << "wrapping only moves line breaks";
  EXPECT_EQ(wrap_text("", 30, "# "), "# \n");
}

// The resolved config: every float shortest (config.toml had 0.69999999999999996 and
// 1.3999999999999999), and bit-identical after to_toml -> parse_config, for the defaults and
// for random values of several keys.
TEST(Text, ResolvedConfigHasShortestFloatsAndRoundTrips) {
  Config def;
  resolve_defaults(def);
  const std::string text = to_toml(def);
  EXPECT_NE(text.find("phi_init = 0.7\n"), std::string::npos) << text;
  EXPECT_NE(text.find("size_ratio = 1.4\n"), std::string::npos) << text;
  std::istringstream lines(text);
  int floats = 0;
  for (std::string line; std::getline(lines, line);) {
    const auto eq = line.find(" = ");
    if (eq == std::string::npos) continue;
    const std::string value = line.substr(eq + 3);
    if (value.find_first_of(".e") == std::string::npos || value[0] == '"') continue;
    EXPECT_TRUE(is_shortest(value, std::strtod(value.c_str(), nullptr))) << line;
    ++floats;
  }
  EXPECT_GT(floats, 30);
  EXPECT_EQ(to_toml(parse_config(text, "defaults.toml")), text);

  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 2000; ++k) {
    Config c;
    c.particles.phi_init = 0.05 + 0.8 * u(rng);
    c.particles.size_ratio = 1.0 + 2.0 * u(rng);
    c.flow.j = std::pow(10.0, -9.0 + 10.0 * u(rng));
    c.flow.lz = 1e-3 + 99.0 * u(rng);
    c.contact.ktilde = std::pow(10.0, 9.0 * u(rng));
    c.contact.mu = 10.0 * u(rng);
    c.run.strain = 1.0 + 1e3 * u(rng);
    c.output.frame_strain = c.run.strain * (1e-3 + u(rng) * 0.5);
    c.analysis.sample_strain = std::min(1.0, c.output.frame_strain / 7.0);
    c.analysis.coarse_strain = c.analysis.msd_window_hi / (5.0 + 100.0 * u(rng));
    const std::string t = to_toml(c);
    const Config back = parse_config(t, "random.toml");
    for (const auto& [a, b] : {std::pair{back.particles.phi_init, c.particles.phi_init},
                               {back.particles.size_ratio, c.particles.size_ratio},
                               {back.flow.j, c.flow.j},
                               {back.flow.lz, c.flow.lz},
                               {back.contact.ktilde, c.contact.ktilde},
                               {back.contact.mu, c.contact.mu},
                               {back.run.strain, c.run.strain},
                               {back.output.frame_strain, c.output.frame_strain}})
      ASSERT_EQ(std::bit_cast<std::uint64_t>(a), std::bit_cast<std::uint64_t>(b)) << t;
    ASSERT_EQ(to_toml(back), t);
    ASSERT_NE(t.find("phi_init = " + fmt::format("{}", c.particles.phi_init) + "\n"),
              std::string::npos)
        << t;
  }
}

// `config-doc` fits a terminal (its table had lines of 309 characters) and is itself a TOML
// file of the defaults.
TEST(Text, ConfigReferenceTextFitsAndParsesToTheDefaults) {
  const std::string text = config_reference_text(100);
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    std::size_t columns = 0;
    for (char c : line) columns += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
    EXPECT_LE(columns, 100u) << line;
  }
  Config def;
  resolve_defaults(def);
  EXPECT_EQ(to_toml(parse_config(text, "config-doc")), to_toml(def));
  // Every key of the table is in the text.
  std::istringstream rows(config_reference_markdown());
  int keys = 0;
  for (std::string row; std::getline(rows, row);) {
    if (row.rfind("| `", 0) != 0) continue;
    const std::string key = row.substr(3, row.find('`', 3) - 3);
    const std::string name = key.substr(key.find('.') + 1);
    EXPECT_NE(text.find("\n" + name + " = "), std::string::npos) << key;
    ++keys;
  }
  EXPECT_GT(keys, 40);
}

}  // namespace
}  // namespace sheardiff

TEST(Text, JsonTextWritesAListOfNumbersOnOneLine) {
  using sheardiff::json_text;
  // Profiles and history rows: one line each (a list with anything else keeps one per line).
  const nlohmann::json js = {{"profile", {0.5, 2.0, nullptr, 3}}, {"mixed", {1, "a"}}};
  EXPECT_EQ(json_text(js),
            "{\n  \"mixed\": [\n    1,\n    \"a\"\n  ],\n  \"profile\": [0.5, 2.0, null, 3]\n}");
  EXPECT_EQ(json_text(js, -1), "{\"mixed\":[1,\"a\"],\"profile\":[0.5,2.0,null,3]}");
  EXPECT_EQ(nlohmann::json::parse(json_text(js)), js);
}
