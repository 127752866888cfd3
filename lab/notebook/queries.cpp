#include "lab/notebook/queries.hpp"

#include <algorithm>
#include <ostream>

namespace rocklab::notebook {

namespace {

Table drain(Statement& s) {
  Table t;
  for (int c = 0; c < s.columns(); ++c) t.columns.push_back(s.columnName(c));
  while (s.step()) {
    std::vector<Cell> row;
    for (int c = 0; c < s.columns(); ++c) row.push_back(s.cell(c));
    t.rows.push_back(std::move(row));
  }
  return t;
}

}  // namespace

Table query(Notebook& nb, const std::string& sql) {
  Table t;
  t.rows = nb.db().query(sql, &t.columns);
  return t;
}

Table readOnlyQuery(const std::string& lab, const std::string& sql) {
  Connection c(lab, Access::ReadOnly);
  Table t;
  t.rows = c.query(sql, &t.columns);
  return t;
}

void requireRun(Notebook& nb, std::int64_t run) {
  auto s = nb.db().prepare("SELECT 1 FROM runs WHERE id = ?");
  s.bind(1, run);
  if (!s.step()) {
    throw SqlError("no run " + std::to_string(run) + " in lab notebook '" + nb.path() +
                   "' (see `rocklab notebook runs`)");
  }
}

Table listRuns(Notebook& nb) {
  return query(nb,
               "SELECT id, protocol, rig, status, started, round(wall_seconds, 1) AS wall_s, "
               "code_version, seed, threads, coalesce(reason, '') AS reason FROM runs ORDER BY id");
}

std::vector<std::pair<std::string, Table>> showRun(Notebook& nb, std::int64_t run) {
  requireRun(nb, run);
  const std::string id = std::to_string(run);
  std::vector<std::pair<std::string, Table>> out;
  out.emplace_back("run", query(nb,
                                "SELECT id, protocol, protocol_file, protocol_hash, rig, status, "
                                "reason, started, finished, wall_seconds, code_version, "
                                "build_type, seed, threads, host FROM runs WHERE id = " +
                                    id));
  out.emplace_back("params", query(nb, "SELECT key, value, unit FROM params WHERE run_id = " + id +
                                           " ORDER BY key"));
  out.emplace_back(
      "results",
      query(nb, "SELECT name, value, unit FROM results WHERE run_id = " + id + " ORDER BY name"));
  out.emplace_back("stage_timings",
                   query(nb,
                         "SELECT stage, round(seconds, 3) AS seconds, calls FROM stage_timings "
                         "WHERE run_id = " +
                             id + " ORDER BY seconds DESC"));
  out.emplace_back("snapshots", query(nb,
                                      "SELECT step, time_s, stage, label, kind, path FROM "
                                      "snapshots WHERE run_id = " +
                                          id + " ORDER BY step"));
  out.emplace_back("messages", query(nb,
                                     "SELECT step, time_s, level, text FROM messages WHERE "
                                     "run_id = " +
                                         id + " ORDER BY step"));
  out.emplace_back("records",
                   query(nb,
                         "SELECT 'series' AS what, name, count(*) AS rows FROM series WHERE "
                         "run_id = " +
                             id +
                             " GROUP BY name UNION ALL SELECT 'events', kind, "
                             "count(*) FROM events WHERE run_id = " +
                             id + " GROUP BY kind"));
  return out;
}

Table seriesOf(Notebook& nb, std::int64_t run, const std::vector<std::string>& names) {
  requireRun(nb, run);
  std::string sql =
      "SELECT name, step, time_s, value FROM series WHERE run_id = " + std::to_string(run);
  if (!names.empty()) {
    sql += " AND name IN (";
    for (std::size_t k = 0; k < names.size(); ++k) sql += (k ? ", ?" : "?");
    sql += ")";
  }
  sql += " ORDER BY name, step";
  auto s = nb.db().prepare(sql);
  for (std::size_t k = 0; k < names.size(); ++k) s.bind(static_cast<int>(k + 1), names[k]);
  return drain(s);
}

Table eventsOf(Notebook& nb, std::int64_t run, const std::string& kind) {
  requireRun(nb, run);
  auto s = nb.db().prepare(
      "SELECT step, time_s, stage, kind, mode, x, y, z, particle_a, particle_b, granular, value "
      "FROM events WHERE run_id = ? AND (? = '' OR kind = ?) ORDER BY step, rowid");
  s.bind(1, run).bind(2, kind).bind(3, kind);
  return drain(s);
}

std::vector<EventRecord> eventRecords(Notebook& nb, std::int64_t run, const std::string& kind) {
  requireRun(nb, run);
  auto s = nb.db().prepare(
      "SELECT step, time_s, coalesce(stage, ''), kind, coalesce(mode, ''), x, y, z, particle_a, "
      "particle_b, coalesce(granular, ''), value FROM events WHERE run_id = ? AND kind = ? "
      "ORDER BY rowid");
  s.bind(1, run).bind(2, kind);
  std::vector<EventRecord> out;
  while (s.step()) {
    EventRecord e;
    e.step = static_cast<std::uint64_t>(s.integer(0));
    e.time = s.real(1);
    e.stage = s.text(2), e.kind = s.text(3), e.mode = s.text(4);
    e.x = s.real(5), e.y = s.real(6), e.z = s.real(7);
    e.particle_a = s.isNull(8) ? -1 : s.integer(8);
    e.particle_b = s.isNull(9) ? -1 : s.integer(9);
    e.granular = s.text(10);
    e.value = s.real(11);
    out.push_back(std::move(e));
  }
  return out;
}

std::vector<WaveRecord> wavesOf(Notebook& nb, std::int64_t run) {
  requireRun(nb, run);
  auto ws = nb.db().prepare(
      "SELECT id, step, time_s, stage, name, wave_type, propagation_axis, polarisation_axis, "
      "frequency_hz, amplitude_m_per_s, dt_s, velocity_xcorr_m_per_s, "
      "velocity_first_break_m_per_s, source FROM waves WHERE run_id = ? ORDER BY id");
  ws.bind(1, run);
  auto ts = nb.db().prepare(
      "SELECT t.distance_m, t.particles, t.picked_samples, t.samples, x.time_s, x.quality, "
      "f.time_s FROM traces t "
      "LEFT JOIN picks x ON x.wave_id = t.wave_id AND x.receiver = t.receiver AND x.method = "
      "'xcorr' "
      "LEFT JOIN picks f ON f.wave_id = t.wave_id AND f.receiver = t.receiver AND f.method = "
      "'first_break' "
      "WHERE t.wave_id = ? ORDER BY t.receiver");
  auto optional = [](const Statement& s, int c) {
    return s.isNull(c) ? std::nullopt : std::optional<double>(s.real(c));
  };
  std::vector<WaveRecord> out;
  while (ws.step()) {
    WaveRecord w;
    w.step = static_cast<std::uint64_t>(ws.integer(1));
    w.time = ws.real(2);
    w.stage = ws.text(3), w.name = ws.text(4), w.type = ws.text(5);
    w.propagation_axis = static_cast<int>(ws.integer(6));
    w.polarisation_axis = static_cast<int>(ws.integer(7));
    w.frequency = ws.real(8), w.amplitude = ws.real(9), w.dt = ws.real(10);
    w.velocity_xcorr = optional(ws, 11);
    w.velocity_first_break = optional(ws, 12);
    w.source = ws.doubles(13);
    ts.bind(1, ws.integer(0));
    while (ts.step()) {
      WaveRecord::Receiver r;
      r.distance = ts.real(0);
      r.particles = ts.integer(1);
      r.picked_samples = ts.integer(2);
      r.samples = ts.doubles(3);
      r.xcorr_time = optional(ts, 4);
      r.xcorr_quality = optional(ts, 5);
      r.first_break_time = optional(ts, 6);
      w.receivers.push_back(std::move(r));
    }
    ts.reset();
    out.push_back(std::move(w));
  }
  return out;
}

namespace {

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

void printTable(std::ostream& out, const Table& t, bool csv) {
  if (csv) {
    for (std::size_t c = 0; c < t.columns.size(); ++c)
      out << (c ? "," : "") << csvField(t.columns[c]);
    out << "\n";
    for (const auto& row : t.rows) {
      for (std::size_t c = 0; c < row.size(); ++c) out << (c ? "," : "") << csvField(row[c].str());
      out << "\n";
    }
    return;
  }
  std::vector<std::size_t> width(t.columns.size());
  for (std::size_t c = 0; c < t.columns.size(); ++c) width[c] = t.columns[c].size();
  for (const auto& row : t.rows) {
    for (std::size_t c = 0; c < row.size(); ++c) {
      width[c] = std::min<std::size_t>(60, std::max(width[c], row[c].str().size()));
    }
  }
  auto cell = [&](const std::string& s, std::size_t c, bool last) {
    std::string v = s.size() > 60 ? s.substr(0, 57) + "..." : s;
    out << v;
    if (!last) out << std::string(width[c] - std::min(width[c], v.size()) + 2, ' ');
  };
  for (std::size_t c = 0; c < t.columns.size(); ++c)
    cell(t.columns[c], c, c + 1 == t.columns.size());
  out << "\n";
  for (const auto& row : t.rows) {
    for (std::size_t c = 0; c < row.size(); ++c) cell(row[c].str(), c, c + 1 == row.size());
    out << "\n";
  }
}

}  // namespace rocklab::notebook
