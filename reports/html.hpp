#pragma once
// The HTML pages of reports and studies: escaping, numbers and one style sheet.

#include <cmath>
#include <sstream>
#include <string>

namespace rocklab::reports {

inline std::string html(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '&':
        o += "&amp;";
        break;
      case '"':
        o += "&quot;";
        break;
      default:
        o += c;
    }
  }
  return o;
}

inline std::string num(double v, int precision = 5) {
  if (std::isnan(v)) return "&ndash;";
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}

inline constexpr const char* kStyle = R"(
body { font-family: sans-serif; max-width: 1100px; margin: 2em auto; color: #222; }
h1 { font-size: 1.6em; } h2 { border-bottom: 1px solid #ccc; margin-top: 2em; }
table { border-collapse: collapse; margin: 0.8em 0; font-size: 0.9em; }
td, th { border: 1px solid #ddd; padding: 3px 8px; text-align: left; }
th { background: #f3f3f3; } td.n { text-align: right; font-variant-numeric: tabular-nums; }
figure { margin: 1.5em 0; } figure img { max-width: 100%; border: 1px solid #eee; }
figcaption { font-size: 0.9em; color: #444; margin-top: 0.3em; }
.status-completed { color: #0a7d32; } .status-failed, .status-interrupted { color: #b00020; }
.snap { display: flex; flex-wrap: wrap; gap: 1em; } .snap figure { width: 48%; margin: 0.5em 0; }
details { margin: 0.6em 0; }
)";

// A whole page: `body` under the shared style sheet.
inline std::string page(const std::string& title, const std::string& body) {
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" + html(title) +
         "</title><style>" + kStyle + "</style></head><body>\n" + body + "</body></html>\n";
}

}  // namespace rocklab::reports
