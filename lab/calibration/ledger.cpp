#include "lab/calibration/ledger.hpp"

#include <filesystem>
#include <stdexcept>

namespace rocklab::calibration {

std::vector<double> errors(const Calibration& c, const Evaluation& e) {
  std::vector<double> out;
  for (std::size_t t = 0; t < c.targets.size(); ++t) {
    out.push_back((e.targets.at(t).mean - c.targets[t].value) / c.targets[t].tolerance);
  }
  return out;
}

std::vector<Evaluated> evaluatedPoints(const Calibration& c, const std::vector<Evaluation>& all) {
  std::vector<Evaluated> out;
  for (const Evaluation& e : all) {
    if (!e.counts() || e.status != "evaluated") continue;
    Evaluated x{c.unit(e.values), errors(c, e), {}};
    for (std::size_t t = 0; t < c.targets.size(); ++t) {
      const TargetValue& v = e.targets[t];
      // The variance of a seed mean, in tolerances squared; unknown from one run (0: the
      // surrogate's nugget stands for it).
      const double s = v.n > 1 ? v.std / c.targets[t].tolerance : 0.0;
      x.variance.push_back(s * s / static_cast<double>(std::max<std::int64_t>(1, v.n)));
    }
    out.push_back(std::move(x));
  }
  return out;
}

int bestEvaluation(const std::vector<Evaluation>& all) {
  int best = -1;
  for (const Evaluation& e : all) {
    if (!e.counts() || e.status != "evaluated") continue;
    if (best < 0) {
      best = e.index;
      continue;
    }
    const Evaluation& b = all[static_cast<std::size_t>(best)];
    if (e.within != b.within ? e.within : e.misfit < b.misfit) best = e.index;
  }
  return best;
}

std::int64_t Ledger::find(notebook::Notebook& lab, const std::string& name) {
  auto q = lab.db().prepare("SELECT id FROM calibrations WHERE name = ?");
  q.bind(1, name);
  return q.step() ? q.integer(0) : 0;
}

Ledger::Ledger(notebook::Notebook& lab, const Calibration& c, std::int64_t id)
    : lab_(lab), c_(c), id_(id) {}

Ledger::Ledger(notebook::Notebook& lab, const Calibration& c) : lab_(lab), c_(c) {
  auto q = lab.db().prepare("SELECT id, text, file FROM calibrations WHERE name = ?");
  q.bind(1, c.name);
  if (q.step()) {
    if (q.text(1) != c.text) {
      throw std::runtime_error(
          "calibration " + c.name + " in " + lab.path() + " was run from another text of " +
          q.text(2) +
          ": a calibration goes on only from the same file (give this one another "
          "calibration.name)");
    }
    id_ = q.integer(0);
    return;
  }
  lab.db()
      .prepare(
          "INSERT INTO calibrations (name, file, text, status, updated) VALUES (?, ?, ?, "
          "'running', ?)")
      .bind(1, c.name)
      .bind(2, std::filesystem::absolute(c.file).string())
      .bind(3, c.text)
      .bind(4, notebook::utcNow())
      .run();
  id_ = lab.db().lastInsertId();
}

std::vector<Evaluation> Ledger::load() const {
  std::vector<Evaluation> out;
  auto q = lab_.db().prepare(
      "SELECT evaluation, batch, kind, status, misfit, "
      "coalesce(within_tolerance, 0) FROM calibration_evaluations WHERE calibration_id = ? "
      "ORDER BY evaluation");
  q.bind(1, id_);
  while (q.step()) {
    Evaluation e;
    e.index = static_cast<int>(q.integer(0));
    e.batch = static_cast<int>(q.integer(1));
    e.kind = q.text(2);
    e.status = q.text(3);
    e.misfit = q.isNull(4) ? kNaN : q.real(4);
    e.within = q.integer(5) != 0;
    e.values.assign(c_.parameters.size(), kNaN);
    e.targets.assign(c_.targets.size(), {});
    out.push_back(std::move(e));
  }
  auto v = lab_.db().prepare(
      "SELECT role, name, value, coalesce(n, 0), std, ci95_low, ci95_high FROM "
      "calibration_values WHERE calibration_id = ? AND evaluation = ?");
  for (Evaluation& e : out) {
    v.bind(1, id_).bind(2, e.index);
    while (v.step()) {
      const std::string role = v.text(0), name = v.text(1);
      auto real = [&](int col) { return v.isNull(col) ? kNaN : v.real(col); };
      if (role == "parameter") {
        for (std::size_t k = 0; k < c_.parameters.size(); ++k) {
          if (c_.parameters[k].name == name) e.values[k] = real(2);
        }
      } else {
        for (std::size_t k = 0; k < c_.targets.size(); ++k) {
          if (c_.targets[k].name != name) continue;
          e.targets[k] = {v.integer(3), real(2), real(4), real(5), real(6)};
        }
      }
    }
    v.reset();
  }
  return out;
}

std::vector<Evaluation> Ledger::propose(int batch, const std::vector<std::string>& kinds,
                                        const std::vector<std::vector<double>>& values,
                                        int first_index) {
  std::vector<Evaluation> out;
  notebook::Transaction t(lab_.db());
  auto e = lab_.db().prepare(
      "INSERT INTO calibration_evaluations (calibration_id, evaluation, batch, kind, status) "
      "VALUES (?, ?, ?, ?, 'proposed')");
  auto v = lab_.db().prepare(
      "INSERT INTO calibration_values (calibration_id, evaluation, role, name, value) VALUES "
      "(?, ?, 'parameter', ?, ?)");
  for (std::size_t k = 0; k < values.size(); ++k) {
    Evaluation x;
    x.index = first_index + static_cast<int>(k);
    x.batch = batch;
    x.kind = kinds.at(k);
    x.values = values[k];
    x.targets.assign(c_.targets.size(), {});
    e.bind(1, id_).bind(2, x.index).bind(3, batch).bind(4, x.kind).run();
    for (std::size_t p = 0; p < c_.parameters.size(); ++p) {
      v.bind(1, id_).bind(2, x.index).bind(3, c_.parameters[p].name).bind(4, x.values[p]).run();
    }
    out.push_back(std::move(x));
  }
  lab_.db()
      .prepare("UPDATE calibrations SET updated = ? WHERE id = ?")
      .bind(1, notebook::utcNow())
      .bind(2, id_)
      .run();
  t.commit();
  return out;
}

void Ledger::record(const Evaluation& x) {
  notebook::Transaction t(lab_.db());
  auto e = lab_.db().prepare(
      "UPDATE calibration_evaluations SET status = ?, misfit = ?, within_tolerance = ? WHERE "
      "calibration_id = ? AND evaluation = ?");
  e.bind(1, x.status);
  if (x.status == "evaluated") {
    e.bind(2, x.misfit).bind(3, static_cast<std::int64_t>(x.within));
  } else {
    e.bindNull(2).bindNull(3);
  }
  e.bind(4, id_).bind(5, x.index).run();
  auto v = lab_.db().prepare(
      "INSERT INTO calibration_values (calibration_id, evaluation, role, name, value, n, std, "
      "ci95_low, ci95_high) VALUES (?, ?, 'target', ?, ?, ?, ?, ?, ?) ON CONFLICT "
      "(calibration_id, evaluation, role, name) DO UPDATE SET value = excluded.value, n = "
      "excluded.n, std = excluded.std, ci95_low = excluded.ci95_low, ci95_high = "
      "excluded.ci95_high");
  for (std::size_t k = 0; k < c_.targets.size(); ++k) {
    const TargetValue& tv = x.targets[k];
    v.bind(1, id_).bind(2, x.index).bind(3, c_.targets[k].name).bind(5, tv.n);
    auto real = [&](int col, double value) {
      if (std::isfinite(value)) {
        v.bind(col, value);
      } else {
        v.bindNull(col);
      }
    };
    real(4, tv.mean);
    real(6, tv.std);
    real(7, tv.low);
    real(8, tv.high);
    v.run();
  }
  t.commit();
}

void Ledger::finish(const std::string& status, const std::string& reason, int best,
                    const std::string& material) {
  auto s = lab_.db().prepare(
      "UPDATE calibrations SET status = ?, reason = ?, best_evaluation = ?, material = ?, "
      "updated = ? WHERE id = ?");
  s.bind(1, status).bind(2, reason);
  if (best >= 0) {
    s.bind(3, static_cast<std::int64_t>(best));
  } else {
    s.bindNull(3);
  }
  if (material.empty()) {
    s.bindNull(4);
  } else {
    s.bind(4, material);
  }
  s.bind(5, notebook::utcNow()).bind(6, id_).run();
}

std::string Ledger::status() const {
  auto q = lab_.db().prepare("SELECT status FROM calibrations WHERE id = ?");
  q.bind(1, id_);
  return q.step() ? q.text(0) : "";
}

std::string Ledger::reason() const {
  auto q = lab_.db().prepare("SELECT coalesce(reason, '') FROM calibrations WHERE id = ?");
  q.bind(1, id_);
  return q.step() ? q.text(0) : "";
}

}  // namespace rocklab::calibration
