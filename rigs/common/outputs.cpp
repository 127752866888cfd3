#include "rigs/common/outputs.hpp"

#include <algorithm>
#include <cctype>
#include <sstream>

namespace rocklab::rigs {

namespace {

bool digit(char c) {
  return std::isdigit(static_cast<unsigned char>(c)) != 0;
}
bool word(char c) {
  return std::islower(static_cast<unsigned char>(c)) || digit(c) || c == '_';
}

// Whether all of `text` matches `pattern`: '#' stands for one or more digits, '*' for one
// or more of [a-z0-9_].
bool matches(std::string_view pattern, std::string_view text) {
  if (pattern.empty()) return text.empty();
  const char p = pattern.front();
  if (p != '#' && p != '*') {
    return !text.empty() && text.front() == p && matches(pattern.substr(1), text.substr(1));
  }
  const auto allowed = p == '#' ? digit : word;
  for (std::size_t n = 1; n <= text.size() && allowed(text[n - 1]); ++n) {
    if (matches(pattern.substr(1), text.substr(n))) return true;
  }
  return false;
}

void append(std::vector<OutputDecl>& to, std::initializer_list<OutputDecl> d) {
  to.insert(to.end(), d.begin(), d.end());
}

void appendNew(std::vector<OutputDecl>& to, const std::vector<OutputDecl>& from) {
  for (const OutputDecl& d : from) {
    const bool known =
        std::any_of(to.begin(), to.end(), [&](const OutputDecl& x) { return x.name == d.name; });
    if (!known) to.push_back(d);
  }
}

void list(std::ostringstream& s, const std::vector<OutputDecl>& d) {
  for (const OutputDecl& x : d) {
    s << "  " << x.name << (x.unit == "-" || x.unit.empty() ? "" : " (" + std::string(x.unit) + ")")
      << "\n      " << x.doc << "\n";
  }
}

}  // namespace

bool outputNameMatches(std::string_view pattern, std::string_view name) {
  return matches(pattern, name);
}

Outputs& Outputs::prefixes(std::initializer_list<std::string_view> p) {
  for (std::string_view x : p) {
    if (std::find(prefixes_.begin(), prefixes_.end(), x) == prefixes_.end())
      prefixes_.emplace_back(x);
  }
  return *this;
}
Outputs& Outputs::series(std::initializer_list<OutputDecl> d) {
  append(series_, d);
  return *this;
}
Outputs& Outputs::results(std::initializer_list<OutputDecl> d) {
  append(results_, d);
  return *this;
}
Outputs& Outputs::events(std::initializer_list<OutputDecl> d) {
  append(events_, d);
  return *this;
}
Outputs& Outputs::keyResults(std::initializer_list<OutputDecl> d) {
  append(key_results_, d);
  return *this;
}

Outputs& Outputs::add(const Outputs& other) {
  for (const std::string& p : other.prefixes_) {
    if (std::find(prefixes_.begin(), prefixes_.end(), p) == prefixes_.end()) prefixes_.push_back(p);
  }
  appendNew(series_, other.series_);
  appendNew(results_, other.results_);
  appendNew(events_, other.events_);
  appendNew(key_results_, other.key_results_);
  return *this;
}

const std::vector<OutputDecl>& Outputs::of(OutputKind kind) const {
  switch (kind) {
    case OutputKind::Series:
      return series_;
    case OutputKind::Result:
      return results_;
    case OutputKind::Event:
      break;
  }
  return events_;
}

template <class Visit>
void Outputs::bases(std::string_view name, Visit&& visit) const {
  for (const std::string& p : prefixes_) {
    for (std::size_t n = 0; n <= name.size(); ++n) {
      if (matches(p, name.substr(0, n))) visit(name.substr(n));
    }
  }
}

bool Outputs::declares(OutputKind kind, std::string_view name) const {
  if (kind == OutputKind::Event) {  // events are named by their kind alone
    return std::any_of(events_.begin(), events_.end(),
                       [&](const OutputDecl& d) { return d.name == name; });
  }
  const auto& decls = of(kind);
  bool found = false;
  bases(name, [&](std::string_view base) {
    found = found || std::any_of(decls.begin(), decls.end(),
                                 [&](const OutputDecl& d) { return matches(d.name, base); });
  });
  return found;
}

const OutputDecl* Outputs::keyResult(std::string_view name) const {
  const OutputDecl* found = nullptr;
  bases(name, [&](std::string_view base) {
    for (const OutputDecl& d : key_results_) {
      if (!found && matches(d.name, base)) found = &d;
    }
  });
  return found;
}

std::string Outputs::help() const {
  std::ostringstream s;
  s << "Key results a protocol can name in protocol.key_results (a prefix picks a test, copy or "
       "stage: test2.NAME, cored.NAME, stage3.NAME):\n";
  list(s, key_results_);
  s << "\nRecorded, each name after one of the prefixes";
  for (const std::string& p : prefixes_) s << " " << (p.empty() ? "(none)" : p);
  s << " ('#' stands for a number, '*' for a word)\nSeries:\n";
  list(s, series_);
  s << "Results:\n";
  list(s, results_);
  s << "Events (their kind):\n";
  list(s, events_);
  return s.str();
}

const Outputs* rigOutputs(std::string_view rig) {
  static const std::pair<std::string_view, const Outputs& (*)()> table[] = {
      {"oedometer", oedometer::outputs},
      {"biaxial", biaxial::outputs},
      {"envelope", envelope::outputs},
      {"hydrostatic", hydrostatic::outputs},
      {"permeameter", permeameter::outputs},
      {"ultrasonic", ultrasonic::outputs},
      {"brazilian", brazilian::outputs},
      {"direct_tension", direct_tension::outputs},
      {"ucs", ucs::outputs},
  };
  for (const auto& [name, outputs] : table) {
    if (name == rig) return &outputs();
  }
  return nullptr;
}

}  // namespace rocklab::rigs
