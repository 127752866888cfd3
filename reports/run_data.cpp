#include "reports/run_data.hpp"

#include <cmath>

#include "lab/notebook/queries.hpp"

namespace rocklab::reports {

const SeriesData* RunData::find(const std::string& name) const {
  if (reads) reads->series.insert(name);
  auto it = series.find(name);
  return it == series.end() ? nullptr : &it->second;
}

const Quantity* RunData::result(const std::string& name) const {
  if (reads) reads->results.insert(name);
  auto it = results.find(name);
  return it == results.end() ? nullptr : &it->second;
}

std::string RunData::param(const std::string& key) const {
  if (reads) reads->params.insert(key);
  for (const auto& [k, v, u] : params) {
    if (k == key) return v;
  }
  return "";
}

RunData loadRun(notebook::Notebook& nb, std::int64_t run) {
  notebook::requireRun(nb, run);
  auto& db = nb.db();
  RunData r;
  r.id = run;
  {
    auto s = db.prepare(
        "SELECT protocol, rig, status, coalesce(reason, ''), started, code_version, build_type, "
        "coalesce(wall_seconds, 0), protocol_file FROM runs WHERE id = ?");
    s.bind(1, run);
    s.step();
    r.protocol = s.text(0), r.rig = s.text(1), r.status = s.text(2), r.reason = s.text(3);
    r.started = s.text(4), r.code_version = s.text(5), r.build_type = s.text(6);
    r.wall_seconds = s.real(7), r.protocol_file = s.text(8);
  }
  {
    auto s = db.prepare("SELECT key, value, unit FROM params WHERE run_id = ? ORDER BY key");
    s.bind(1, run);
    while (s.step()) r.params.emplace_back(s.text(0), s.text(1), s.text(2));
  }
  {
    auto s = db.prepare("SELECT name, value, unit FROM results WHERE run_id = ?");
    s.bind(1, run);
    while (s.step()) r.results[s.text(0)] = {s.isNull(1) ? NAN : s.real(1), s.text(2)};
  }
  {
    auto s = db.prepare(
        "SELECT stage, seconds, calls FROM stage_timings WHERE run_id = ? ORDER BY seconds DESC");
    s.bind(1, run);
    while (s.step()) r.timings.emplace_back(s.text(0), s.real(1), s.integer(2));
  }
  {
    auto s = db.prepare("SELECT level, text FROM messages WHERE run_id = ? ORDER BY step");
    s.bind(1, run);
    while (s.step()) r.messages.emplace_back(s.text(0), s.text(1));
  }
  {
    auto s =
        db.prepare("SELECT name, step, value FROM series WHERE run_id = ? ORDER BY name, step");
    s.bind(1, run);
    while (s.step()) {
      SeriesData& d = r.series[s.text(0)];
      d.step.push_back(static_cast<std::uint64_t>(s.integer(1)));
      d.value.push_back(s.isNull(2) ? NAN : s.real(2));
    }
  }
  {
    auto s = db.prepare(
        "SELECT step, time_s, stage, label, path FROM snapshots WHERE run_id = ? AND kind = "
        "'frame' ORDER BY rowid");
    s.bind(1, run);
    while (s.step()) {
      r.snapshots.push_back({static_cast<std::uint64_t>(s.integer(0)), s.real(1), s.text(2),
                             s.text(3), nb.resolve(s.text(4))});
    }
  }
  r.breaks = notebook::eventRecords(nb, run, "bond_break");
  r.pores = notebook::eventRecords(nb, run, "pore_pressure");
  r.waves = notebook::wavesOf(nb, run);
  return r;
}

void pair(const RunData& r, const std::string& x, const std::string& y, std::vector<double>& xs,
          std::vector<double>& ys, double x_scale, double y_scale) {
  xs.clear();
  ys.clear();
  const SeriesData* sx = r.find(x);
  const SeriesData* sy = r.find(y);
  if (!sx || !sy) return;
  std::size_t j = 0;
  for (std::size_t i = 0; i < sx->step.size(); ++i) {
    while (j < sy->step.size() && sy->step[j] < sx->step[i]) ++j;
    if (j < sy->step.size() && sy->step[j] == sx->step[i]) {
      xs.push_back(sx->value[i] * x_scale);
      ys.push_back(sy->value[j] * y_scale);
    }
  }
}

}  // namespace rocklab::reports
