// libFuzzer target for the config parser and validator (issue 6): arbitrary bytes go to
// sheardiff::parse_config. A ConfigError is the expected answer to bad input; any other
// exception, a crash or a sanitizer report is a finding.
//
// Input layout: the bytes up to the first NUL are the TOML document; what follows is a list of
// --set overrides, one per line, so that the override path is fuzzed too.
//
// An accepted document must round-trip: to_toml(cfg) parses again (no ConfigError) and gives
// the same text, i.e. the resolved configuration that a run writes to DIR/config.toml is itself
// a valid configuration with the same values.
//
// Built by tests/fuzz/CMakeLists.txt (-fsanitize=fuzzer,address,undefined, clang only).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <string_view>
#include <vector>

#include "sheardiff/config.hpp"

namespace {

[[noreturn]] void finding(const char* what, const std::string& detail) {
  std::fprintf(stderr, "FUZZ FINDING: %s: %s\n", what, detail.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  const auto nul = all.find('\0');
  const std::string text(all.substr(0, nul));
  std::vector<std::string> overrides;
  if (nul != std::string_view::npos) {
    std::string_view rest = all.substr(nul + 1);
    while (!rest.empty() && overrides.size() < 8) {
      const auto eol = rest.find('\n');
      overrides.emplace_back(rest.substr(0, eol));
      if (eol == std::string_view::npos) break;
      rest.remove_prefix(eol + 1);
    }
  }

  sheardiff::Config cfg;
  try {
    cfg = sheardiff::parse_config(text, "fuzz.toml", overrides);
  } catch (const sheardiff::ConfigError&) {
    return 0;  // rejected: the expected outcome for bad input
  } catch (const std::exception& e) {
    finding("parse_config threw an exception other than ConfigError", e.what());
  } catch (...) {
    finding("parse_config threw a non-std exception", "");
  }

  // Accepted: the resolved configuration must parse back to itself.
  const std::string resolved = sheardiff::to_toml(cfg);
  try {
    const sheardiff::Config again = sheardiff::parse_config(resolved, "resolved.toml");
    const std::string resolved_again = sheardiff::to_toml(again);
    if (resolved_again != resolved)
      finding("to_toml/parse_config round trip changed the configuration",
              "first:\n" + resolved + "\nsecond:\n" + resolved_again);
  } catch (const sheardiff::ConfigError& e) {
    finding("the resolved configuration (to_toml) of an accepted input is rejected",
            std::string(e.what()) + "\n" + resolved);
  } catch (const std::exception& e) {
    finding("re-parsing the resolved configuration threw", e.what());
  }
  return 0;
}
