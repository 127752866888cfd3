#pragma once
// A thin RAII layer over the SQLite C API: a connection, prepared statements with typed
// binds, and errors that carry SQLite's message.

#include <sqlite3.h>

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace rocklab::notebook {

class SqlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A cell of a query result.
struct Cell {
  enum class Type { Null, Integer, Real, Text } type = Type::Null;
  std::int64_t integer = 0;
  double real = 0.0;
  std::string text;
  std::string str() const;  // as printed in tables and CSV
};

class Statement {
 public:
  Statement(sqlite3* db, std::string_view sql);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  Statement(Statement&& o) noexcept : db_(o.db_), stmt_(o.stmt_) { o.stmt_ = nullptr; }

  Statement& bind(int index, std::int64_t v);
  Statement& bind(int index, int v) { return bind(index, static_cast<std::int64_t>(v)); }
  Statement& bind(int index, std::uint64_t v) { return bind(index, static_cast<std::int64_t>(v)); }
  Statement& bind(int index, double v);
  Statement& bind(int index, std::string_view v);
  Statement& bind(int index, const char* v) { return bind(index, std::string_view(v)); }
  Statement& bindNull(int index);
  // Samples as a BLOB of little-endian float64 (this machine's order, checked at build).
  Statement& bindDoubles(int index, const std::vector<double>& v);
  template <class T>
  Statement& bind(int index, const std::optional<T>& v) {
    return v ? bind(index, *v) : bindNull(index);
  }

  // Steps once; true while a row is available.
  bool step();
  bool readOnly() const { return sqlite3_stmt_readonly(stmt_) != 0; }
  // Runs to completion and resets, ready for new binds.
  void run();
  void reset();

  int columns() const;
  std::string columnName(int c) const;
  Cell cell(int c) const;
  std::int64_t integer(int c) const { return sqlite3_column_int64(stmt_, c); }
  double real(int c) const { return sqlite3_column_double(stmt_, c); }
  std::string text(int c) const;
  bool isNull(int c) const { return sqlite3_column_type(stmt_, c) == SQLITE_NULL; }
  std::vector<double> doubles(int c) const;  // a BLOB written by bindDoubles

 private:
  void check(int rc, const char* what) const;
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

// How a connection may touch its file. ReadOnly refuses, before anything runs, every
// statement that would change the file or the connection (ATTACH, DETACH, a PRAGMA that
// sets something): what a user types into `rocklab notebook sql` cannot lose the lab.
enum class Access { ReadOnly, ReadWrite, Create };

class Connection {
 public:
  Connection(const std::string& path, Access access);
  ~Connection();
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  void exec(std::string_view sql);
  Statement prepare(std::string_view sql) { return Statement(db_, sql); }
  std::int64_t lastInsertId() const { return sqlite3_last_insert_rowid(db_); }
  int userVersion();
  const std::string& path() const { return path_; }
  bool readOnly() const { return read_only_; }

  // All rows of a query, with the column names first.
  std::vector<std::vector<Cell>> query(std::string_view sql, std::vector<std::string>* names);

 private:
  sqlite3* db_ = nullptr;
  std::string path_;
  bool read_only_ = false;
};

// A transaction that rolls back unless committed.
class Transaction {
 public:
  explicit Transaction(Connection& c) : c_(c) { c_.exec("BEGIN IMMEDIATE"); }
  ~Transaction() {
    if (!done_) {
      try {
        c_.exec("ROLLBACK");
      } catch (...) {
      }
    }
  }
  void commit() {
    c_.exec("COMMIT");
    done_ = true;
  }

 private:
  Connection& c_;
  bool done_ = false;
};

}  // namespace rocklab::notebook
