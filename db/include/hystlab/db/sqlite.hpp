#pragma once
// RAII over the SQLite C API (as SQLiteCpp): a connection, prepared statements, and a
// transaction that rolls back unless committed. Errors throw DbError with SQLite's message.
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

struct sqlite3;
struct sqlite3_stmt;

namespace hystlab::db {

struct DbError : std::runtime_error {
  DbError(const std::string& what, int sqlite_code) : std::runtime_error(what), code(sqlite_code) {}
  int code;
};

class Database {
 public:
  // Opens (creating) the file; WAL journal, foreign keys on, busy timeout 5 s.
  explicit Database(const std::string& path, bool synchronous_full = true);
  ~Database();
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  void exec(std::string_view sql);
  [[nodiscard]] std::int64_t last_insert_rowid() const noexcept;
  [[nodiscard]] sqlite3* handle() const noexcept { return db_; }
  [[nodiscard]] const std::string& path() const noexcept { return path_; }

 private:
  sqlite3* db_ = nullptr;
  std::string path_;
};

class Statement {
 public:
  Statement(Database& db, std::string_view sql);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int index, std::int64_t v);
  Statement& bind(int index, int v) { return bind(index, static_cast<std::int64_t>(v)); }
  Statement& bind(int index, double v);
  Statement& bind(int index, std::string_view v);
  Statement& bind_null(int index);
  // true while there is a row; false when done. Throws on errors.
  bool step();
  void reset();  // for reuse; keeps bindings unless rebound
  [[nodiscard]] std::int64_t column_int(int c) const;
  [[nodiscard]] double column_double(int c) const;
  [[nodiscard]] std::string column_text(int c) const;
  [[nodiscard]] bool column_is_null(int c) const;
  enum class Type { integer, real, text, blob, null };
  [[nodiscard]] Type column_type(int c) const noexcept;
  [[nodiscard]] std::string_view column_view(int c) const;  // text, valid until the next step

 private:
  sqlite3_stmt* st_ = nullptr;
  Database& db_;
};

class Transaction {
 public:
  explicit Transaction(Database& db, bool immediate = true);
  ~Transaction();  // rolls back unless commit() was called
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void commit();

 private:
  Database& db_;
  bool done_ = false;
};

}  // namespace hystlab::db
