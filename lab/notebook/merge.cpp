#include "lab/notebook/merge.hpp"

#include <filesystem>
#include <map>

namespace rocklab::notebook {

namespace fs = std::filesystem;

namespace {

// The columns of a table of the target's schema (the source's is the same: same version),
// without those the merge gives anew.
std::vector<std::string> columnsOf(Connection& db, const std::string& table,
                                   const std::vector<std::string>& skip) {
  std::vector<std::string> out;
  auto s = db.prepare("SELECT name FROM pragma_table_info(?)");
  s.bind(1, table);
  while (s.step()) {
    const std::string c = s.text(0);
    bool skipped = false;
    for (const auto& k : skip) skipped = skipped || k == c;
    if (!skipped) out.push_back(c);
  }
  return out;
}

std::string joined(const std::vector<std::string>& columns, const std::string& prefix = "") {
  std::string out;
  for (const auto& c : columns) out += (out.empty() ? "" : ", ") + prefix + c;
  return out;
}

// The tables whose rows belong to a run by run_id, besides runs and waves (waves carry the
// traces and picks by their own id). run_origins is the target's account of the merge.
constexpr const char* kRunTables[] = {"params",  "series",   "events",    "stage_timings",
                                      "results", "messages", "snapshots", "inputs"};

// A file path of the source (relative to its folder, inside its run's files) as the target
// keeps it: the same file under the target's run folder.
std::string movedPath(const std::string& path, const fs::path& source_run_dir,
                      const fs::path& source_dir, const fs::path& target_run_dir,
                      const fs::path& target_dir) {
  const fs::path inside = fs::relative(source_dir / path, source_run_dir);
  if (inside.empty() || *inside.begin() == "..") return path;  // not a file of the run's own
  return fs::relative(target_run_dir / inside, target_dir).string();
}

}  // namespace

MergeOutcome mergeNotebook(Notebook& into, const std::string& source, const Provenance& origin) {
  if (fs::equivalent(fs::absolute(source), fs::absolute(into.path()))) {
    throw SqlError("a notebook cannot be merged into itself ('" + source + "')");
  }
  {
    Notebook up_to_date(source);  // migrated to this schema; orphaned runs closed
  }
  Connection& db = into.db();
  db.prepare("ATTACH DATABASE ? AS src").bind(1, source).run();
  struct Detach {
    Connection& db;
    ~Detach() {
      try {
        db.exec("DETACH DATABASE src");
      } catch (...) {
      }
    }
  } detach{db};

  const fs::path source_dir = fs::absolute(source).parent_path();
  const fs::path target_dir = fs::absolute(into.path()).parent_path();
  const std::string source_files = fs::absolute(source).string() + ".files";
  const std::vector<std::string> run_columns = columnsOf(db, "runs", {"id"});
  const std::vector<std::string> wave_columns = columnsOf(db, "waves", {"id", "run_id"});
  std::vector<std::pair<std::string, std::vector<std::string>>> run_tables;
  for (const char* table : kRunTables)
    run_tables.emplace_back(table, columnsOf(db, table, {"run_id"}));
  std::vector<std::pair<std::string, std::vector<std::string>>> wave_tables;
  for (const char* table : {"traces", "picks"}) {
    wave_tables.emplace_back(table, columnsOf(db, table, {"wave_id"}));
  }

  MergeOutcome out;
  std::vector<fs::path> copied;    // removed if the merge fails
  std::vector<fs::path> replaced;  // files of runs merged anew, set aside until it commits
  try {
    Transaction t(db);
    auto runs =
        db.prepare("SELECT id, uuid, status, coalesce(finished, '') FROM src.runs ORDER BY id");
    while (runs.step()) {
      const std::int64_t old_id = runs.integer(0);
      const std::string uuid = runs.text(1);
      if (runs.text(2) == "running") {
        throw SqlError("run " + std::to_string(old_id) + " of '" + source +
                       "' is still running: merge it once it has ended");
      }
      auto known =
          db.prepare("SELECT id, status, coalesce(finished, '') FROM main.runs WHERE uuid = ?");
      known.bind(1, uuid);
      if (known.step()) {
        // The same run: once completed, or ended as it ended here, it is there already. A
        // run that has gone on since (resumed after a failure) replaces what was merged.
        if (known.text(1) == "completed" || known.text(2) == runs.text(3)) {
          ++out.already;
          continue;
        }
        db.prepare("DELETE FROM main.runs WHERE id = ?").bind(1, known.integer(0)).run();
        // Its files step aside (its id may be the new run's): gone once the merge commits,
        // back if it fails.
        const fs::path dir = fs::absolute(into.runFilesDir(known.integer(0)));
        if (fs::exists(dir)) {
          fs::rename(dir, dir.string() + ".replaced");
          replaced.push_back(dir);
        }
      }
      db.prepare("INSERT INTO main.runs (" + joined(run_columns) + ") SELECT " +
                 joined(run_columns) + " FROM src.runs WHERE id = ?")
          .bind(1, old_id)
          .run();
      const std::int64_t id = db.lastInsertId();
      for (const auto& [table, columns] : run_tables) {
        db.prepare("INSERT INTO main." + table + " (run_id, " + joined(columns) + ") SELECT ?, " +
                   joined(columns) + " FROM src." + table + " WHERE run_id = ?")
            .bind(1, id)
            .bind(2, old_id)
            .run();
      }
      // Waves get new ids; their traces and picks follow them.
      std::map<std::int64_t, std::int64_t> wave_ids;
      auto waves = db.prepare("SELECT id FROM src.waves WHERE run_id = ? ORDER BY id");
      waves.bind(1, old_id);
      while (waves.step()) {
        db.prepare("INSERT INTO main.waves (run_id, " + joined(wave_columns) + ") SELECT ?, " +
                   joined(wave_columns) + " FROM src.waves WHERE id = ?")
            .bind(1, id)
            .bind(2, waves.integer(0))
            .run();
        wave_ids[waves.integer(0)] = db.lastInsertId();
      }
      for (const auto& [table, columns] : wave_tables) {
        auto copy = db.prepare("INSERT INTO main." + table + " (wave_id, " + joined(columns) +
                               ") SELECT ?, " + joined(columns) + " FROM src." + table +
                               " WHERE wave_id = ?");
        for (const auto& [from, to] : wave_ids) copy.bind(1, to).bind(2, from).run();
      }
      // The run's files, and the paths the notebook keeps of them.
      const fs::path from_dir = fs::path(source_files) / ("run-" + std::to_string(old_id));
      const fs::path to_dir = fs::absolute(into.runFilesDir(id));
      if (fs::exists(from_dir)) {
        if (fs::exists(to_dir)) {
          throw SqlError("'" + to_dir.string() + "' exists though run " + std::to_string(id) +
                         " is new: files of a deleted run were left there; remove them");
        }
        fs::create_directories(to_dir.parent_path());
        copied.push_back(to_dir);
        fs::copy(from_dir, to_dir, fs::copy_options::recursive);
      }
      for (const auto& [table, column] :
           {std::pair{"snapshots", "path"}, std::pair{"inputs", "copy"}}) {
        auto rows = db.prepare(std::string("SELECT rowid, ") + column + " FROM main." + table +
                               " WHERE run_id = ?");
        rows.bind(1, id);
        auto update = db.prepare(std::string("UPDATE main.") + table + " SET " + column +
                                 " = ? WHERE rowid = ?");
        while (rows.step()) {
          update
              .bind(1,
                    movedPath(rows.text(1), fs::absolute(from_dir), source_dir, to_dir, target_dir))
              .bind(2, rows.integer(0))
              .run();
        }
      }
      auto o = db.prepare(
          "INSERT INTO main.run_origins (run_id, notebook, source_run, scheduler, job_id, "
          "task_id) VALUES (?, ?, ?, ?, ?, ?)");
      o.bind(1, id).bind(2, fs::absolute(source).string()).bind(3, old_id);
      o.bind(4, origin.scheduler);
      if (origin.job_id.empty()) {
        o.bindNull(5);
      } else {
        o.bind(5, origin.job_id);
      }
      if (origin.task_id < 0) {
        o.bindNull(6);
      } else {
        o.bind(6, origin.task_id);
      }
      o.run();
      out.runs.push_back(id);
      out.source_runs.push_back(old_id);
    }
    t.commit();
    for (const auto& d : replaced) fs::remove_all(d.string() + ".replaced");
  } catch (...) {
    for (const auto& d : copied) fs::remove_all(d);
    for (const auto& d : replaced) fs::rename(d.string() + ".replaced", d);
    throw;
  }
  return out;
}

void removeNotebook(const std::string& path) {
  for (const std::string suffix : kNotebookParts) fs::remove_all(path + suffix);
}

}  // namespace rocklab::notebook
