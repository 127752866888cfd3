#include "lab/calibration/material_file.hpp"

#include <algorithm>
#include <array>
#include <sstream>
#include <stdexcept>

namespace rocklab::calibration {

namespace {

std::string trimmed(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return {};
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

// "[bonds]  # why" -> "bonds"; empty when the line is not a table header.
std::string headerOf(const std::string& line) {
  const std::string t = trimmed(line);
  if (t.size() < 3 || t[0] != '[' || t[1] == '[') return {};
  const auto close = t.find(']');
  if (close == std::string::npos) return {};
  const std::string rest = trimmed(t.substr(close + 1));
  if (!rest.empty() && rest[0] != '#') return {};
  return trimmed(t.substr(1, close - 1));
}

// "modulus_GPa = 4.0  # why" -> "modulus_GPa"; empty when the line gives no plain key.
std::string keyOf(const std::string& line) {
  const std::string t = trimmed(line);
  if (t.empty() || t[0] == '#' || t[0] == '[') return {};
  const auto eq = t.find('=');
  if (eq == std::string::npos) return {};
  std::string k = trimmed(t.substr(0, eq));
  if (k.size() >= 2 && k.front() == '"' && k.back() == '"') k = k.substr(1, k.size() - 2);
  return k;
}

}  // namespace

bool isMaterialKey(const std::string& key) {
  static const std::array<const char*, 5> tables = {"material.", "bonds.", "grain_bonds.",
                                                    "grains.", "clumps."};
  return std::any_of(tables.begin(), tables.end(),
                     [&](const char* t) { return key.rfind(t, 0) == 0; });
}

std::string materialText(const std::string& previous, const std::string& header,
                         const std::vector<std::pair<std::string, std::string>>& keys) {
  std::vector<std::string> lines;
  {
    std::istringstream in(previous);
    for (std::string l; std::getline(in, l);) lines.push_back(l);
  }
  // The old header: the comments before the first blank line or table.
  std::size_t body = 0;
  while (body < lines.size() && trimmed(lines[body]).rfind('#', 0) == 0) ++body;
  while (body < lines.size() && trimmed(lines[body]).empty()) ++body;
  lines.erase(lines.begin(), lines.begin() + static_cast<std::ptrdiff_t>(body));

  std::vector<std::vector<std::string>> after(lines.size() + 1);  // to insert after line k
  std::string appended;
  for (const auto& [key, value] : keys) {
    const auto dot = key.rfind('.');
    if (dot == std::string::npos)
      throw std::invalid_argument("material key without a table: " + key);
    const std::string table = key.substr(0, dot), leaf = key.substr(dot + 1);
    std::string current;
    std::size_t header_at = lines.size() + 1;  // none
    bool placed = false;
    for (std::size_t k = 0; k < lines.size() && !placed; ++k) {
      if (const std::string h = headerOf(lines[k]); !h.empty()) {
        current = h;
        if (h == table) header_at = k;
        continue;
      }
      const std::string given = keyOf(lines[k]);
      if (current == table && given == leaf) {
        lines[k] = leaf + " = " + value;
        placed = true;
      } else if (current.empty() && given == key) {
        throw std::invalid_argument("the material file gives " + key +
                                    " as a dotted key; give it in its table [" + table + "]");
      }
    }
    if (placed) continue;
    if (header_at < lines.size()) {
      after[header_at + 1].push_back(leaf + " = " + value);
    } else if (appended.find("\n[" + table + "]\n") == std::string::npos) {
      appended += "\n[" + table + "]\n" + leaf + " = " + value + "\n";
    } else {
      const auto at = appended.find("\n[" + table + "]\n") + table.size() + 4;
      appended.insert(at, leaf + " = " + value + "\n");
    }
  }
  while (!lines.empty() && trimmed(lines.back()).empty()) lines.pop_back();
  std::ostringstream out;
  out << header;
  if (!header.empty() && header.back() != '\n') out << "\n";
  if (!lines.empty()) out << "\n";
  for (std::size_t k = 0; k <= lines.size(); ++k) {
    for (const std::string& l : after[k]) out << l << "\n";
    if (k < lines.size()) out << lines[k] << "\n";
  }
  return out.str() + appended;
}

}  // namespace rocklab::calibration
