#include "reports/ensemble.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <optional>
#include <regex>
#include <sstream>

#include "lab/campaign/statistics.hpp"

namespace rocklab::reports {

namespace {

using campaign::summarize;

// Points on a common abscissa per branch: enough for a smooth curve, few enough for the CSV.
constexpr std::size_t kGridPoints = 120;
// A reversal of the abscissa smaller than this share of its range is noise (a servo's
// jitter), not a new branch (an unloading).
constexpr double kReversal = 0.02;

std::string shortNumber(double v) {
  std::ostringstream s;
  s.precision(3);
  s << v;
  return s.str();
}

// The monotonic branches of a curve's abscissa, [first, last] index pairs: a new branch
// starts where x turns back by more than kReversal of its range from its extreme so far.
std::vector<std::pair<std::size_t, std::size_t>> branchesOf(const std::vector<double>& x) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  if (x.empty()) return out;
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  const double tol = kReversal * (*hi - *lo);
  std::size_t start = 0, extreme = 0;
  int dir = 0;
  for (std::size_t i = 1; i < x.size(); ++i) {
    if (dir == 0) {
      if (std::abs(x[i] - x[start]) > tol) dir = x[i] > x[start] ? 1 : -1, extreme = i;
      continue;
    }
    if ((x[i] - x[extreme]) * dir > 0) {
      extreme = i;
    } else if ((x[extreme] - x[i]) * dir > tol) {
      out.emplace_back(start, extreme);
      start = extreme, extreme = i, dir = -dir;
    }
  }
  out.emplace_back(start, x.size() - 1);
  return out;
}

// y at each of `grid` along one branch of a curve, linearly between its points sorted by x.
std::vector<double> sample(const Series& s, std::pair<std::size_t, std::size_t> branch,
                           const std::vector<double>& grid) {
  std::vector<std::pair<double, double>> xy;
  for (std::size_t i = branch.first; i <= branch.second; ++i) xy.emplace_back(s.x[i], s.y[i]);
  std::stable_sort(xy.begin(), xy.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<double> out;
  for (double g : grid) {
    auto it = std::lower_bound(xy.begin(), xy.end(), g,
                               [](const auto& p, double v) { return p.first < v; });
    if (it == xy.end()) it = std::prev(it);
    if (it == xy.begin() || it->first == g) {
      out.push_back(it->second);
      continue;
    }
    const auto& [x1, y1] = *it;
    const auto& [x0, y0] = *std::prev(it);
    out.push_back(y0 + (y1 - y0) * (g - x0) / (x1 - x0));
  }
  return out;
}

void addSpread(Series& out, const std::vector<std::vector<double>>& values) {
  for (std::size_t k = 0; k < values.front().size(); ++k) {
    std::vector<double> at;
    for (const auto& v : values) at.push_back(v[k]);
    const campaign::Summary m = summarize(at);
    out.y.push_back(m.mean);
    out.low.push_back(m.mean - m.std);
    out.high.push_back(m.mean + m.std);
  }
}

// Curves: the mean over the members on a grid over the range every member covers, branch by
// branch; none when the members' branches differ in number or direction.
std::optional<Series> meanCurve(const std::vector<const Series*>& members) {
  std::vector<std::vector<std::pair<std::size_t, std::size_t>>> branches;
  for (const Series* s : members) branches.push_back(branchesOf(s->x));
  Series out;
  std::vector<std::vector<double>> values(members.size());
  for (std::size_t b = 0; b < branches.front().size(); ++b) {
    double from = -INFINITY, to = INFINITY;
    int dir = 0;
    for (std::size_t m = 0; m < members.size(); ++m) {
      if (branches[m].size() != branches.front().size()) return std::nullopt;
      const auto [first, last] = branches[m][b];
      const std::vector<double>& x = members[m]->x;
      const int d = x[last] >= x[first] ? 1 : -1;
      if (dir != 0 && d != dir) return std::nullopt;
      dir = d;
      const auto [lo, hi] = std::minmax_element(x.begin() + first, x.begin() + last + 1);
      from = std::max(from, *lo), to = std::min(to, *hi);
    }
    if (!(to >= from)) return std::nullopt;
    std::vector<double> grid;
    for (std::size_t k = 0; k < kGridPoints; ++k) {
      const double t = static_cast<double>(k) / (kGridPoints - 1);
      grid.push_back(dir > 0 ? from + t * (to - from) : to - t * (to - from));
    }
    out.x.insert(out.x.end(), grid.begin(), grid.end());
    for (std::size_t m = 0; m < members.size(); ++m) {
      const std::vector<double> y = sample(*members[m], branches[m][b], grid);
      values[m].insert(values[m].end(), y.begin(), y.end());
    }
  }
  addSpread(out, values);
  return out;
}

// Points: each the mean of the members' k-th point; none when their counts differ.
std::optional<Series> meanPoints(const std::vector<const Series*>& members) {
  Series out;
  out.markers = true;
  std::vector<std::vector<double>> values;
  for (const Series* s : members) {
    if (s->x.size() != members.front()->x.size()) return std::nullopt;
    values.push_back(s->y);
  }
  for (std::size_t k = 0; k < members.front()->x.size(); ++k) {
    std::vector<double> at;
    for (const Series* s : members) at.push_back(s->x[k]);
    out.x.push_back(summarize(at).mean);
  }
  addSpread(out, values);
  return out;
}

// The members' labels as one: where they differ only in numbers, each such number becomes
// "mean +- std" over the members; otherwise the first's.
std::string combineLabels(const std::vector<std::string>& labels) {
  static const std::regex number(R"([-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)");
  std::vector<std::vector<std::string>> texts, numbers;
  for (const std::string& l : labels) {
    std::vector<std::string> text, nums;
    std::size_t at = 0;
    for (auto it = std::sregex_iterator(l.begin(), l.end(), number); it != std::sregex_iterator();
         ++it) {
      text.push_back(l.substr(at, static_cast<std::size_t>(it->position()) - at));
      nums.push_back(it->str());
      at = static_cast<std::size_t>(it->position() + it->length());
    }
    text.push_back(l.substr(at));
    texts.push_back(std::move(text));
    numbers.push_back(std::move(nums));
  }
  for (const auto& t : texts) {
    if (t != texts.front()) return labels.front();
  }
  std::string out;
  for (std::size_t k = 0; k < numbers.front().size(); ++k) {
    out += texts.front()[k];
    std::vector<double> v;
    bool same = true;
    for (const auto& n : numbers) {
      v.push_back(std::stod(n[k]));
      same = same && n[k] == numbers.front()[k];
    }
    if (same) {
      out += numbers.front()[k];
    } else {
      const campaign::Summary m = summarize(v);
      out += shortNumber(m.mean) + " +- " + shortNumber(m.std);
    }
  }
  return out + texts.front().back();
}

bool identical(const std::vector<const Series*>& members) {
  for (const Series* s : members) {
    if (s->x != members.front()->x || s->y != members.front()->y) return false;
  }
  return true;
}

std::optional<Series> combineSeries(const std::vector<const Series*>& members) {
  std::vector<std::string> labels;
  for (const Series* s : members) labels.push_back(s->label);
  if (identical(members)) return *members.front();  // a value of the paper's, a setting
  std::optional<Series> out = members.front()->markers ? meanPoints(members) : meanCurve(members);
  if (out) out->label = combineLabels(labels);
  return out;
}

// The members' series matched to the first's: by place when every panel holds as many,
// else by label; none when a series has no match in some member.
std::optional<std::vector<std::vector<const Series*>>> matchSeries(
    const std::vector<const Panel*>& panels) {
  const std::size_t n = panels.front()->series.size();
  bool by_place = true;
  for (const Panel* p : panels) by_place = by_place && p->series.size() == n;
  std::vector<std::vector<const Series*>> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    for (const Panel* p : panels) {
      const Series* match = nullptr;
      if (by_place) {
        match = &p->series[k];
      } else {
        for (const Series& s : p->series) {
          if (s.label == panels.front()->series[k].label) match = &s;
        }
      }
      if (!match || match->markers != panels.front()->series[k].markers || match->x.empty()) {
        return std::nullopt;
      }
      out[k].push_back(match);
    }
  }
  return out;
}

// One panel over the runs: each series combined, or none when some series cannot be.
std::optional<Panel> combinePanel(const std::vector<const Panel*>& panels) {
  const auto matched = matchSeries(panels);
  if (!matched) return std::nullopt;
  Panel out = *panels.front();
  out.series.clear();
  for (const auto& group : *matched) {
    std::optional<Series> s = combineSeries(group);
    if (!s) return std::nullopt;
    out.series.push_back(std::move(*s));
  }
  return out;
}

Figure figureWithoutRun(Figure f, std::int64_t run) {
  f.id = withoutRun(f.id, run);
  f.title = withoutRun(f.title, run);
  for (Panel& p : f.panels) {
    for (Series& s : p.series) s.label = withoutRun(s.label, run);
  }
  return f;
}

std::string runList(const std::vector<RunFigures>& runs) {
  std::string s;
  for (const RunFigures& r : runs) s += (s.empty() ? "" : ", ") + std::to_string(r.run);
  return s;
}

}  // namespace

std::string withoutRun(const std::string& text, std::int64_t run) {
  const std::string id = std::to_string(run);
  // The length of a mention at `at`: "run 12" as a word with the spaces after it, or
  // "-run12" in an id; 0 for none.
  auto mentionAt = [&](std::size_t at) -> std::size_t {
    for (const std::string& m : {"run " + id, "-run" + id}) {
      std::size_t end = at + m.size();
      if (text.compare(at, m.size(), m) != 0) continue;
      if (end < text.size() && std::isdigit(static_cast<unsigned char>(text[end]))) continue;
      if (m[0] == '-') return m.size();
      if (at > 0 && std::isalnum(static_cast<unsigned char>(text[at - 1]))) continue;
      while (end < text.size() && text[end] == ' ') ++end;
      return end - at;
    }
    return 0;
  };
  std::string out;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t skip = mentionAt(at);
    if (skip > 0) {
      at += skip;
    } else {
      out += text[at++];
    }
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == ',')) out.pop_back();
  return out;
}

std::vector<Figure> combineFigures(const std::vector<RunFigures>& runs) {
  std::vector<Figure> out;
  if (runs.empty()) return out;
  std::vector<std::vector<Figure>> named;
  for (const RunFigures& r : runs) {
    std::vector<Figure> figures;
    for (const Figure& f : r.figures) figures.push_back(figureWithoutRun(f, r.run));
    named.push_back(std::move(figures));
  }
  const std::string list = runList(runs);
  for (const Figure& first : named.front()) {
    // Each run's figure of this id, with its names (for a mean) and as the run drew it (to
    // overlay a panel a mean would misstate).
    std::vector<const Figure*> members, originals;
    for (std::size_t r = 0; r < runs.size(); ++r) {
      for (std::size_t k = 0; k < named[r].size(); ++k) {
        if (named[r][k].id != first.id) continue;
        members.push_back(&named[r][k]);
        originals.push_back(&runs[r].figures[k]);
      }
    }
    bool same_panels = members.size() == runs.size() && runs.size() > 1;
    for (const Figure* f : members)
      same_panels = same_panels && f->panels.size() == first.panels.size();
    Figure f = first;
    std::vector<std::size_t> overlaid;
    for (std::size_t p = 0; p < f.panels.size(); ++p) {
      std::optional<Panel> combined;
      if (same_panels) {
        std::vector<const Panel*> panels;
        for (const Figure* m : members) panels.push_back(&m->panels[p]);
        combined = combinePanel(panels);
      }
      if (combined) {
        f.panels[p] = std::move(*combined);
        continue;
      }
      // The runs' series as each labelled them, drawn together.
      f.panels[p].series.clear();
      for (const Figure* o : originals) {
        if (p >= o->panels.size()) continue;
        const auto& series = o->panels[p].series;
        f.panels[p].series.insert(f.panels[p].series.end(), series.begin(), series.end());
      }
      overlaid.push_back(p + 1);
    }
    if (overlaid.size() < f.panels.size()) {
      f.caption += " Over " + std::to_string(runs.size()) + " seeds (runs " + list +
                   "): each curve is the mean of the runs' curves on a common abscissa, over "
                   "the range every run reached, and its band one standard deviation either "
                   "side; each point the mean of the runs' with a bar of one standard "
                   "deviation; numbers in a legend are mean +- standard deviation.";
    }
    if (!overlaid.empty()) {
      std::string which;
      for (std::size_t p : overlaid) {
        if (!which.empty()) which += ", ";
        which += std::to_string(p);
      }
      f.caption += overlaid.size() == f.panels.size() ? " The" : " In panel " + which + ", the";
      f.caption += " seeds' runs (" + list +
                   ") are overlaid: their curves differ in shape (other branches, abscissa "
                   "ranges that do not meet, other point counts), so they are not averaged.";
    }
    out.push_back(std::move(f));
  }
  return out;
}

}  // namespace rocklab::reports
