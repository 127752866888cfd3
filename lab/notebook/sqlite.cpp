#include "lab/notebook/sqlite.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <sstream>

namespace rocklab::notebook {

std::string Cell::str() const {
  switch (type) {
    case Type::Null:
      return "";
    case Type::Integer:
      return std::to_string(integer);
    case Type::Real: {
      std::ostringstream s;
      s.precision(10);
      s << real;
      return s.str();
    }
    case Type::Text:
      return text;
  }
  return "";
}

Statement::Statement(sqlite3* db, std::string_view sql) : db_(db) {
  const int rc = sqlite3_prepare_v2(db_, sql.data(), static_cast<int>(sql.size()), &stmt_, nullptr);
  if (rc != SQLITE_OK) {
    throw SqlError(std::string(sqlite3_errmsg(db_)) + " in: " + std::string(sql));
  }
}

Statement::~Statement() {
  if (stmt_) sqlite3_finalize(stmt_);
}

void Statement::check(int rc, const char* what) const {
  if (rc != SQLITE_OK) throw SqlError(std::string(what) + ": " + sqlite3_errmsg(db_));
}

Statement& Statement::bind(int index, std::int64_t v) {
  check(sqlite3_bind_int64(stmt_, index, v), "bind");
  return *this;
}

Statement& Statement::bind(int index, double v) {
  // SQLite stores NaN as NULL; say so explicitly.
  if (std::isnan(v)) return bindNull(index);
  check(sqlite3_bind_double(stmt_, index, v), "bind");
  return *this;
}

Statement& Statement::bind(int index, std::string_view v) {
  check(sqlite3_bind_text(stmt_, index, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT),
        "bind");
  return *this;
}

static_assert(std::endian::native == std::endian::little,
              "traces are stored as little-endian float64 BLOBs");

Statement& Statement::bindDoubles(int index, const std::vector<double>& v) {
  check(sqlite3_bind_blob64(stmt_, index, v.data(), v.size() * sizeof(double), SQLITE_TRANSIENT),
        "bind");
  return *this;
}

std::vector<double> Statement::doubles(int c) const {
  const auto bytes = static_cast<std::size_t>(sqlite3_column_bytes(stmt_, c));
  std::vector<double> v(bytes / sizeof(double));
  if (!v.empty()) std::memcpy(v.data(), sqlite3_column_blob(stmt_, c), v.size() * sizeof(double));
  return v;
}

Statement& Statement::bindNull(int index) {
  check(sqlite3_bind_null(stmt_, index), "bind");
  return *this;
}

bool Statement::step() {
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  throw SqlError(std::string("step: ") + sqlite3_errmsg(db_));
}

void Statement::run() {
  while (step()) {
  }
  reset();
}

void Statement::reset() {
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
}

int Statement::columns() const {
  return sqlite3_column_count(stmt_);
}

std::string Statement::columnName(int c) const {
  return sqlite3_column_name(stmt_, c);
}

std::string Statement::text(int c) const {
  const auto* p = sqlite3_column_text(stmt_, c);
  return p ? std::string(reinterpret_cast<const char*>(p)) : std::string();
}

Cell Statement::cell(int c) const {
  Cell x;
  switch (sqlite3_column_type(stmt_, c)) {
    case SQLITE_INTEGER:
      x.type = Cell::Type::Integer;
      x.integer = integer(c);
      break;
    case SQLITE_FLOAT:
      x.type = Cell::Type::Real;
      x.real = real(c);
      break;
    case SQLITE_NULL:
      break;
    case SQLITE_BLOB:  // samples: shown by size, read with doubles()
      x.type = Cell::Type::Text;
      x.text = "<" + std::to_string(sqlite3_column_bytes(stmt_, c)) + " bytes>";
      break;
    default:
      x.type = Cell::Type::Text;
      x.text = text(c);
  }
  return x;
}

Connection::Connection(const std::string& path, bool create) : path_(path) {
  const int flags = SQLITE_OPEN_READWRITE | (create ? SQLITE_OPEN_CREATE : 0);
  if (sqlite3_open_v2(path.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
    const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw SqlError("cannot open lab notebook '" + path + "': " + why);
  }
  sqlite3_busy_timeout(db_, 10000);  // another writer (a second run in the same lab) waits
}

Connection::~Connection() {
  if (db_) sqlite3_close(db_);
}

void Connection::exec(std::string_view sql) {
  char* err = nullptr;
  const std::string s(sql);
  if (sqlite3_exec(db_, s.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string why = err ? err : "unknown error";
    sqlite3_free(err);
    throw SqlError(why + " in: " + s.substr(0, 200));
  }
}

int Connection::userVersion() {
  Statement s(db_, "PRAGMA user_version");
  s.step();
  return static_cast<int>(s.integer(0));
}

std::vector<std::vector<Cell>> Connection::query(std::string_view sql,
                                                 std::vector<std::string>* names) {
  Statement s(db_, sql);
  if (names) {
    names->clear();
    for (int c = 0; c < s.columns(); ++c) names->push_back(s.columnName(c));
  }
  std::vector<std::vector<Cell>> rows;
  while (s.step()) {
    std::vector<Cell> row;
    for (int c = 0; c < s.columns(); ++c) row.push_back(s.cell(c));
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace rocklab::notebook
