#include <fmt/format.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "sheardiff/io/h5md.hpp"

namespace sheardiff {

namespace {

constexpr std::string_view kSpace = " \t\r\v\f";

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t pos = line.find_first_not_of(kSpace);
  while (pos != std::string_view::npos) {
    const std::size_t end = line.find_first_of(kSpace, pos);
    out.push_back(line.substr(pos, end == std::string_view::npos ? end : end - pos));
    pos = line.find_first_not_of(kSpace, end);
  }
  return out;
}

bool parse_double(std::string_view tok, double& value) {
  // from_chars rejects a leading '+', which hand-written tables do contain.
  if (tok.size() > 1 && tok.front() == '+' && tok[1] != '-' && tok[1] != '+') tok.remove_prefix(1);
  const char* end = tok.data() + tok.size();
  const auto [ptr, ec] = std::from_chars(tok.data(), end, value);
  return ec == std::errc() && ptr == end && std::isfinite(value);
}

[[noreturn]] void fail(const std::filesystem::path& file, long line_no, std::string_view what) {
  throw std::runtime_error(
      fmt::format("position table '{}', line {}: {}", file.string(), line_no, what));
}

}  // namespace

TableConfiguration read_position_table(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) {
    throw std::runtime_error(fmt::format("position table '{}': cannot open file: {}", file.string(),
                                         std::strerror(errno)));
  }
  TableConfiguration cfg;
  std::string line;
  long line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::string_view content(line);
    if (const auto hash = content.find('#'); hash != std::string_view::npos) {
      content = content.substr(0, hash);
    }
    const auto tok = split(content);
    if (tok.empty()) continue;
    if (tok.size() != 3) {
      fail(file, line_no, fmt::format("expected 3 columns 'x y diameter', found {}", tok.size()));
    }
    double v[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) {
      if (!parse_double(tok[k], v[k])) {
        fail(file, line_no, fmt::format("column {} '{}' is not a finite number", k + 1, tok[k]));
      }
    }
    if (v[2] <= 0) fail(file, line_no, fmt::format("diameter {} must be positive", v[2]));
    cfg.position.emplace_back(v[0], v[1]);
    cfg.diameter.push_back(v[2]);
  }
  if (in.bad()) {
    throw std::runtime_error(
        fmt::format("position table '{}': read error: {}", file.string(), std::strerror(errno)));
  }
  return cfg;
}

}  // namespace sheardiff
