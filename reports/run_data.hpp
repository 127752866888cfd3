#pragma once
// What a report reads of a run from the notebook.

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "lab/notebook/notebook.hpp"

namespace rocklab::reports {

struct Quantity {
  double value = 0.0;
  std::string unit;
};

struct SeriesData {
  std::vector<std::uint64_t> step;
  std::vector<double> value;
};

struct SnapshotRow {
  std::uint64_t step = 0;
  double time = 0.0;
  std::string stage, label, path;  // path resolved against the notebook
};

// The names a reader asked of a run (RunData::reads): the tests hold the report figures'
// reads to the rigs' declared outputs, so a figure asking for a series no rig writes fails.
struct Reads {
  std::set<std::string> series, results, params;
};

struct RunData {
  std::int64_t id = 0;
  std::string protocol, rig, status, reason, started, code_version, build_type, protocol_file;
  double wall_seconds = 0.0;
  std::vector<std::tuple<std::string, std::string, std::string>> params;  // key, value, unit
  std::map<std::string, Quantity> results;
  std::vector<std::tuple<std::string, double, std::int64_t>> timings;  // stage, seconds, calls
  std::vector<std::pair<std::string, std::string>> messages;           // level, text
  std::map<std::string, SeriesData> series;
  std::vector<SnapshotRow> snapshots;
  std::vector<notebook::EventRecord> breaks;  // bond breaks
  std::vector<notebook::EventRecord> pores;   // steady pore pressures (value), by stage
  std::vector<notebook::WaveRecord> waves;    // ultrasonic measurements with traces and picks

  mutable Reads* reads = nullptr;  // when set, every lookup below is noted in it

  std::string label() const { return "run " + std::to_string(id) + " " + protocol; }
  const SeriesData* find(const std::string& name) const;
  const Quantity* result(const std::string& name) const;
  std::string param(const std::string& key) const;
};

RunData loadRun(notebook::Notebook& nb, std::int64_t run);

// The values of series `y` against series `x`, aligned on their steps.
void pair(const RunData& r, const std::string& x, const std::string& y, std::vector<double>& xs,
          std::vector<double>& ys, double x_scale = 1.0, double y_scale = 1.0);

}  // namespace rocklab::reports
