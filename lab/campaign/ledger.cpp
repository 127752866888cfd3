#include "lab/campaign/ledger.hpp"

#include <cmath>
#include <filesystem>
#include <map>

#include "lab/campaign/statistics.hpp"
#include "reports/key_results.hpp"
#include "reports/run_data.hpp"
#include "rigs/registry.hpp"

namespace rocklab::campaign {

std::string taskProtocolHash(const Campaign& c, const Task& t) {
  return notebook::hashText(rigs::checkProtocol(c.protocol, c.overrides(t)).settings.identity());
}

std::int64_t registerCampaign(notebook::Notebook& lab, const Campaign& c) {
  auto& db = lab.db();
  db.prepare(
        "INSERT INTO campaigns (name, file, text, protocol, updated) VALUES (?, ?, ?, ?, ?) "
        "ON CONFLICT (name) DO UPDATE SET file = excluded.file, text = excluded.text, "
        "protocol = excluded.protocol, updated = excluded.updated")
      .bind(1, c.name)
      .bind(2, std::filesystem::absolute(c.file).string())
      .bind(3, c.text)
      .bind(4, std::filesystem::absolute(c.protocol).string())
      .bind(5, notebook::utcNow())
      .run();
  auto s = db.prepare("SELECT id FROM campaigns WHERE name = ?");
  s.bind(1, c.name);
  s.step();
  return s.integer(0);
}

namespace {

// The hash a run is known by now, from the protocol text the notebook kept: for runs noted
// when the hash was of the text, so that a notebook kept from then does not run its
// campaigns again. Each run read once; "" for a text that no longer reads.
class KeptHashes {
 public:
  explicit KeptHashes(notebook::Notebook& lab)
      : q_(lab.db().prepare("SELECT id, status, coalesce(reason, ''), protocol_file, "
                            "protocol_text FROM runs WHERE seed = ? AND protocol = ? AND rig = ? "
                            "ORDER BY status = 'completed' DESC, id DESC")) {}

  // The task's run among those of its seed and protocol name, by their settings.
  bool find(TaskState& t, const std::string& name, const std::string& rig) {
    q_.bind(1, t.task.seed).bind(2, name).bind(3, rig);
    bool found = false;
    while (!found && q_.step()) {
      const std::int64_t id = q_.integer(0);
      auto it = hashes_.find(id);
      if (it == hashes_.end()) {
        std::string h;
        try {
          h = notebook::hashText(
              rigs::checkProtocolText(q_.text(3), q_.text(4)).settings.identity());
        } catch (const std::exception&) {
        }
        it = hashes_.emplace(id, h).first;
      }
      if (it->second == t.hash) {
        t.run = id, t.status = q_.text(1), t.reason = q_.text(2);
        found = true;
      }
    }
    q_.reset();
    return found;
  }

 private:
  notebook::Statement q_;
  std::map<std::int64_t, std::string> hashes_;
};

}  // namespace

std::vector<TaskState> survey(notebook::Notebook& lab, const Campaign& c,
                              const std::vector<std::string>& hashes) {
  std::vector<TaskState> out;
  // The completed run first, else the latest.
  auto s = lab.db().prepare(
      "SELECT id, status, coalesce(reason, '') FROM runs WHERE protocol_hash = ? AND seed = ? "
      "ORDER BY status = 'completed' DESC, id DESC LIMIT 1");
  KeptHashes kept(lab);
  const std::vector<Task> tasks = c.tasks();
  for (std::size_t k = 0; k < tasks.size(); ++k) {
    TaskState t{tasks[k], hashes.at(k), 0, "", ""};
    s.bind(1, t.hash).bind(2, t.task.seed);
    if (s.step()) {
      t.run = s.integer(0);
      t.status = s.text(1);
      t.reason = s.text(2);
    } else {
      const rigs::CheckedProtocol p = rigs::checkProtocol(c.protocol, c.overrides(tasks[k]));
      kept.find(t, p.settings.text("protocol.name"), std::string(p.rig->name));
    }
    s.reset();
    out.push_back(std::move(t));
  }
  return out;
}

void recordTask(notebook::Notebook& lab, std::int64_t campaign, const Campaign& c,
                const TaskState& t) {
  auto s = lab.db().prepare(
      "INSERT INTO campaign_points (campaign_id, point, seed, settings, protocol_hash, run_id) "
      "VALUES (?, ?, ?, ?, ?, ?) ON CONFLICT (campaign_id, point, seed) DO UPDATE SET "
      "settings = excluded.settings, protocol_hash = excluded.protocol_hash, "
      "run_id = excluded.run_id");
  s.bind(1, campaign).bind(2, t.task.point).bind(3, t.task.seed);
  s.bind(4, c.points.at(static_cast<std::size_t>(t.task.point)).label()).bind(5, t.hash);
  if (t.run > 0) {
    s.bind(6, t.run);
  } else {
    s.bindNull(6);
  }
  s.run();
}

namespace {

// A completed run's numbers: every recorded result, and each key result of its protocol that
// a rule evaluates from its series (reports/key_results.hpp) rather than records.
void addRunValues(notebook::Notebook& lab, std::int64_t run,
                  std::map<std::string, std::pair<std::string, std::vector<double>>>& by_name) {
  const reports::RunData r = reports::loadRun(lab, run);
  for (const auto& [name, q] : r.results) {
    if (!std::isfinite(q.value)) continue;
    auto& [unit, values] = by_name[name];
    unit = q.unit;
    values.push_back(q.value);
  }
  for (const reports::KeyValue& k : reports::keyResults(r)) {
    if (!k.value || r.results.count(k.name)) continue;
    auto& [unit, values] = by_name[k.name];
    unit = k.unit;
    values.push_back(*k.value);
  }
}

}  // namespace

void updateStatistics(notebook::Notebook& lab, std::int64_t campaign, const Campaign& c) {
  auto& db = lab.db();
  notebook::Transaction tx(db);
  db.prepare("DELETE FROM campaign_statistics WHERE campaign_id = ?").bind(1, campaign).run();
  auto runs = db.prepare(
      "SELECT p.run_id FROM campaign_points p JOIN runs u ON u.id = p.run_id WHERE "
      "p.campaign_id = ? AND p.point = ? AND u.status = 'completed' ORDER BY p.seed");
  auto insert = db.prepare(
      "INSERT INTO campaign_statistics (campaign_id, point, settings, name, unit, n, mean, std, "
      "ci95_low, ci95_high) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  for (const Point& p : c.points) {
    std::vector<std::int64_t> ids;
    runs.bind(1, campaign).bind(2, p.index);
    while (runs.step()) ids.push_back(runs.integer(0));
    runs.reset();
    std::map<std::string, std::pair<std::string, std::vector<double>>> by_name;
    for (std::int64_t id : ids) addRunValues(lab, id, by_name);
    for (const auto& [name, entry] : by_name) {
      const Summary m = summarize(entry.second);
      insert.bind(1, campaign).bind(2, p.index).bind(3, p.label()).bind(4, name);
      insert.bind(5, entry.first).bind(6, static_cast<std::int64_t>(m.n)).bind(7, m.mean);
      if (m.n < 2) {
        insert.bind(8, m.std).bindNull(9).bindNull(10);
      } else {
        insert.bind(8, m.std).bind(9, m.low).bind(10, m.high);
      }
      insert.run();
    }
  }
  tx.commit();
}

}  // namespace rocklab::campaign
