#include "lab/notebook/sqlite.hpp"

#include <bit>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
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
  const char* tail = nullptr;
  const int rc = sqlite3_prepare_v2(db_, sql.data(), static_cast<int>(sql.size()), &stmt_, &tail);
  if (rc != SQLITE_OK) {
    throw SqlError(std::string(sqlite3_errmsg(db_)) + " in: " + std::string(sql));
  }
  // A second statement after the first would be ignored silently.
  for (const char* c = tail; c && c < sql.data() + sql.size(); ++c) {
    if (*c != ';' && !std::isspace(static_cast<unsigned char>(*c))) {
      sqlite3_finalize(stmt_);
      stmt_ = nullptr;
      throw SqlError("one statement at a time, not: " + std::string(sql));
    }
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
      // snprintf, not string concatenation: GCC 12 warns falsely (-Wrestrict) on the latter.
      char size[32];
      std::snprintf(size, sizeof size, "<%d bytes>", sqlite3_column_bytes(stmt_, c));
      x.text = size;
      break;
    default:
      x.type = Cell::Type::Text;
      x.text = text(c);
  }
  return x;
}

namespace {

// The pragmas that only read, with or without an argument naming a table or index.
bool pragmaReads(const char* name, const char* argument) {
  static const char* const introspection[] = {
      "table_info",     "table_xinfo",      "table_list",      "index_list",  "index_info",
      "index_xinfo",    "foreign_key_list", "integrity_check", "quick_check", "database_list",
      "collation_list", "function_list",    "module_list",     "pragma_list", "compile_options"};
  for (const char* p : introspection) {
    if (sqlite3_stricmp(name, p) == 0) return true;
  }
  return argument == nullptr;  // `PRAGMA user_version` reads; `PRAGMA user_version = 3` writes
}

// The authorizer of a read-only connection (sqlite.org/c3ref/set_authorizer.html): denies
// what the READONLY open flag lets through, since ATTACH and DETACH change the connection
// rather than the file and some pragmas write before the flag is consulted.
extern "C" int denyChanges(void*, int action, const char* a1, const char* a2, const char*,
                           const char*) {
  switch (action) {
    case SQLITE_ATTACH:
    case SQLITE_DETACH:
      return SQLITE_DENY;
    case SQLITE_PRAGMA:
      return pragmaReads(a1, a2) ? SQLITE_OK : SQLITE_DENY;
    default:
      return SQLITE_OK;
  }
}

}  // namespace

Connection::Connection(const std::string& path, Access access)
    : path_(path), read_only_(access == Access::ReadOnly) {
  const int flags = access == Access::ReadOnly ? SQLITE_OPEN_READONLY
                    : access == Access::Create ? SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE
                                               : SQLITE_OPEN_READWRITE;
  if (sqlite3_open_v2(path.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
    const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    db_ = nullptr;
    throw SqlError("cannot open lab notebook '" + path + "': " + why);
  }
  sqlite3_busy_timeout(db_, 10000);  // another writer (a second run in the same lab) waits
  if (read_only_) sqlite3_set_authorizer(db_, denyChanges, nullptr);
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
  const std::string refused = "the lab notebook '" + path_ +
                              "' is open read-only here: this statement would change it (runs "
                              "are removed with `rocklab notebook delete RUN --yes`)";
  std::optional<Statement> prepared;
  try {
    prepared.emplace(db_, sql);
  } catch (const SqlError&) {
    if (read_only_ && sqlite3_errcode(db_) == SQLITE_AUTH) throw SqlError(refused);
    throw;
  }
  Statement& s = *prepared;
  if (read_only_ && !s.readOnly()) throw SqlError(refused);
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
