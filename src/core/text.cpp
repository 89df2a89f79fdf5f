#include "sheardiff/core/text.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <sstream>

namespace sheardiff {

std::string duration_text(double seconds) {
  if (!(seconds >= 0.0) || seconds > 1e8) return "?";
  const long t = std::lround(seconds);
  if (t >= 3600) return fmt::format("{}h{:02d}m", t / 3600, (t % 3600) / 60);
  if (t >= 60) return fmt::format("{}m{:02d}s", t / 60, t % 60);
  return fmt::format("{}s", t);
}

std::string iso8601_utc(std::chrono::system_clock::time_point t) {
  const std::time_t s = std::chrono::system_clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&s, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string host_name() {
  char host[256] = {};
  if (gethostname(host, sizeof host - 1) != 0 || host[0] == '\0') return "?";
  return host;
}

namespace {
// Shortest round-trip text of a finite double (fmt's default, Dragonbox) that a reader takes
// for a float: "2" becomes "2.0".
std::string float_text(double x) {
  std::string t = fmt::format("{}", x);
  if (t.find_first_of(".eE") == std::string::npos) t += ".0";
  return t;
}
}  // namespace

std::string toml_float(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  return float_text(x);
}

std::string toml_string(std::string_view s) {
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\f':
        out += "\\f";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if ((static_cast<unsigned char>(c) < 0x20) || c == 0x7f)
          out += fmt::format("\\u{:04X}", static_cast<unsigned>(static_cast<unsigned char>(c)));
        else
          out += c;
    }
  }
  return out + "\"";
}

namespace {
void write_json(std::ostringstream& os, const nlohmann::json& js, int indent, int depth) {
  const auto newline = [&](int level) {
    if (indent >= 0) os << '\n' << std::string(static_cast<std::size_t>(indent * level), ' ');
  };
  if (js.is_object() || js.is_array()) {
    const bool object = js.is_object();
    if (js.empty()) {
      os << (object ? "{}" : "[]");
      return;
    }
    // A list of numbers (a profile, one row of a history) on one line: one number per line
    // made the channel's profile histories several times larger and no easier to read.
    if (!object && std::all_of(js.begin(), js.end(), [](const nlohmann::json& e) {
          return e.is_number() || e.is_null();
        })) {
      os << '[';
      for (auto it = js.begin(); it != js.end(); ++it) {
        if (it != js.begin()) os << (indent >= 0 ? ", " : ",");
        write_json(os, *it, indent, depth + 1);
      }
      os << ']';
      return;
    }
    os << (object ? '{' : '[');
    bool first = true;
    for (auto it = js.begin(); it != js.end(); ++it) {
      if (!first) os << ',';
      first = false;
      newline(depth + 1);
      if (object) os << nlohmann::json(it.key()).dump() << (indent >= 0 ? ": " : ":");
      write_json(os, *it, indent, depth + 1);
    }
    newline(depth);
    os << (object ? '}' : ']');
  } else if (js.is_number_float()) {
    const double x = js.get<double>();
    os << (std::isfinite(x) ? float_text(x) : "null");
  } else {
    os << js.dump();
  }
}
}  // namespace

std::string json_text(const nlohmann::json& js, int indent) {
  std::ostringstream os;
  write_json(os, js, indent, 0);
  return os.str();
}

std::string wrap_text(std::string_view text, std::size_t width, std::string_view indent) {
  const auto length = [](std::string_view s) {
    std::size_t n = 0;
    for (const char c : s) n += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
    return n;
  };
  std::string out, line(indent);
  std::size_t used = length(indent);
  const std::size_t start = used;
  std::size_t pos = 0;
  while (pos < text.size()) {
    if (text[pos] == ' ') {
      ++pos;
      continue;
    }
    const std::size_t end = std::min(text.find(' ', pos), text.size());
    const std::string_view word = text.substr(pos, end - pos);
    pos = end;
    const std::size_t w = length(word);
    if (used > start && used + 1 + w > width) {
      out += line + '\n';
      line = indent;
      used = start;
    }
    if (used > start) line += ' ', ++used;
    line += word;
    used += w;
  }
  if (used > start || out.empty()) out += line + '\n';
  return out;
}

}  // namespace sheardiff
