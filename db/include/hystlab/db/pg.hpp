#pragma once
// RAII over libpq (as sqlite.hpp over SQLite): a connection, a result, a transaction that rolls
// back unless committed, and COPY FROM STDIN. Errors throw PgError with the server's message and
// its SQLSTATE, so that a caller can tell a lost link (class 08) from a refused statement.
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

struct pg_conn;
struct pg_result;

namespace hystlab::db {

struct PgError : std::runtime_error {
  PgError(const std::string& what, std::string state) : std::runtime_error(what), sqlstate(std::move(state)) {}
  std::string sqlstate;  // e.g. "28P01" a wrong password, "08006" a lost connection; empty: not from the server
};

class PgResult {
 public:
  explicit PgResult(pg_result* r) noexcept : r_(r) {}
  ~PgResult();
  PgResult(PgResult&& o) noexcept : r_(o.r_) { o.r_ = nullptr; }
  PgResult& operator=(PgResult&&) = delete;
  PgResult(const PgResult&) = delete;
  PgResult& operator=(const PgResult&) = delete;
  [[nodiscard]] int rows() const noexcept;
  [[nodiscard]] bool is_null(int row, int col) const noexcept;
  [[nodiscard]] std::string text(int row, int col) const;
  [[nodiscard]] std::int64_t integer(int row, int col) const;  // throws PgError when not a whole number

 private:
  pg_result* r_;
};

class PgConnection {
 public:
  // conninfo: a URL or key=value string; password: empty for libpq's own (~/.pgpass, PGPASSWORD).
  // Throws PgError with libpq's reason (wrong password, no server, ...), the password never in it.
  PgConnection(const std::string& conninfo, const std::string& password, int connect_timeout_s = 5);
  ~PgConnection();
  PgConnection(const PgConnection&) = delete;
  PgConnection& operator=(const PgConnection&) = delete;

  void exec(std::string_view sql);
  // A statement with text parameters (nullptr: NULL); the result of a query.
  PgResult query(std::string_view sql, const std::vector<const char*>& params = {});
  // COPY ... FROM STDIN in text format: rows already encoded (tab-separated, \N for NULL, '\n'
  // ended). Returns the rows the server took.
  std::int64_t copy_in(std::string_view copy_sql, std::string_view rows);
  [[nodiscard]] bool ok() const noexcept;
  [[nodiscard]] pg_conn* handle() const noexcept { return c_; }
  [[nodiscard]] int server_version() const noexcept;

 private:
  pg_conn* c_ = nullptr;
};

// COPY ... FROM STDIN streamed: rows handed over in pieces as they are encoded, so that the server
// parses one piece while the caller reads and encodes the next (a whole batch encoded first, then
// sent, ran at 0.75 of a bare streamed COPY: bench_replication). Ended by finish(); a COPY left
// unfinished (an exception) is ended with an error, so the server rolls it back.
class PgCopy {
 public:
  PgCopy(PgConnection& c, std::string_view copy_sql);
  ~PgCopy();
  PgCopy(const PgCopy&) = delete;
  PgCopy& operator=(const PgCopy&) = delete;
  void put(std::string_view rows);
  std::int64_t finish();  // the rows the server took

 private:
  PgConnection& c_;
  bool open_ = true;
};

class PgTransaction {
 public:
  explicit PgTransaction(PgConnection& c);
  ~PgTransaction();  // rolls back unless commit() was called (a lost link: nothing to roll back)
  PgTransaction(const PgTransaction&) = delete;
  PgTransaction& operator=(const PgTransaction&) = delete;
  void commit();

 private:
  PgConnection& c_;
  bool done_ = false;
};

// True when conninfo (a URL or key=value pairs) holds a password: postgresql://user:secret@host/db,
// ...?password=..., or password=... The config and the CLI refuse such a conninfo, each in its
// own words: a password belongs in a file or the environment, never in a config or a command line.
[[nodiscard]] bool conninfo_has_password(std::string_view conninfo) noexcept;

// COPY's text format for one field: backslash, tab, newline and carriage return escaped.
void append_copy_text(std::string& out, std::string_view field);
// A double as the shortest text that reads back to the same bits (std::to_chars); NaN and the
// infinities as PostgreSQL spells them.
void append_copy_double(std::string& out, double v);

}  // namespace hystlab::db
