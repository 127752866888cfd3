#pragma once
// What `rocklab notebook` shows: tables from the notebook, printed aligned or as CSV.

#include <iosfwd>
#include <string>
#include <vector>

#include "lab/notebook/notebook.hpp"

namespace rocklab::notebook {

struct Table {
  std::vector<std::string> columns;
  std::vector<std::vector<Cell>> rows;
};

Table query(Notebook& nb, const std::string& sql);
// A query a user typed, on a read-only connection to the notebook file `lab`: a statement
// that would change the notebook is refused before it runs (SqlError saying so).
Table readOnlyQuery(const std::string& lab, const std::string& sql);
Table listRuns(Notebook& nb);
// The run's row, then its parameters, results, stage timings and record counts.
std::vector<std::pair<std::string, Table>> showRun(Notebook& nb, std::int64_t run);
Table seriesOf(Notebook& nb, std::int64_t run, const std::vector<std::string>& names);
Table eventsOf(Notebook& nb, std::int64_t run, const std::string& kind);
// The run's events of one kind, in the order recorded.
std::vector<EventRecord> eventRecords(Notebook& nb, std::int64_t run, const std::string& kind);
// The run's ultrasonic measurements with their traces and picks, in the order recorded.
std::vector<WaveRecord> wavesOf(Notebook& nb, std::int64_t run);
// Throws when the run does not exist, naming the lab.
void requireRun(Notebook& nb, std::int64_t run);

void printTable(std::ostream& out, const Table& t, bool csv);

}  // namespace rocklab::notebook
