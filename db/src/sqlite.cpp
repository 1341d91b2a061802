#include <fcntl.h>
#include <unistd.h>

#include "hystlab/db/sqlite.hpp"

#include <sqlite3.h>

namespace hystlab::db {
namespace {
[[noreturn]] void fail(sqlite3* db, int rc, const std::string& what) { throw DbError(what + ": " + (db ? sqlite3_errmsg(db) : sqlite3_errstr(rc)), rc); }
}  // namespace

Database::Database(const std::string& path, bool synchronous_full) : path_(path) {
  // A new file is the owner's alone (0600): it holds the lab's data and the commands for its rigs.
  // SQLite gives its -wal and -shm files the database file's mode.
  if (!path.empty() && path != ":memory:") {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd >= 0) ::close(fd);
  }
  const int rc = sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX, nullptr);
  if (rc != SQLITE_OK) {
    const std::string msg = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
    sqlite3_close(db_);
    db_ = nullptr;
    throw DbError("cannot open database '" + path + "': " + msg, rc);
  }
  sqlite3_busy_timeout(db_, 5000);
  try {
    exec("PRAGMA journal_mode=WAL");
    exec(synchronous_full ? "PRAGMA synchronous=FULL" : "PRAGMA synchronous=NORMAL");
    exec("PRAGMA foreign_keys=ON");
  } catch (...) {  // a constructor that throws runs no destructor: the handle is closed here
    sqlite3_close_v2(db_);
    db_ = nullptr;
    throw;
  }
}

Database::~Database() { sqlite3_close_v2(db_); }

void Database::exec(std::string_view sql) {
  char* err = nullptr;
  const std::string s(sql);
  if (sqlite3_exec(db_, s.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
    const std::string msg = err ? err : "unknown error";
    sqlite3_free(err);
    throw DbError("database '" + path_ + "': " + msg, sqlite3_errcode(db_));
  }
}

std::int64_t Database::last_insert_rowid() const noexcept { return sqlite3_last_insert_rowid(db_); }

Statement::Statement(Database& db, std::string_view sql) : db_(db) {
  const int rc = sqlite3_prepare_v2(db.handle(), sql.data(), static_cast<int>(sql.size()), &st_, nullptr);
  if (rc != SQLITE_OK) fail(db.handle(), rc, "prepare '" + std::string(sql.substr(0, 60)) + "'");
}

Statement::~Statement() { sqlite3_finalize(st_); }

Statement& Statement::bind(int i, std::int64_t v) {
  if (const int rc = sqlite3_bind_int64(st_, i, v); rc != SQLITE_OK) fail(db_.handle(), rc, "bind");
  return *this;
}
Statement& Statement::bind(int i, double v) {
  if (const int rc = sqlite3_bind_double(st_, i, v); rc != SQLITE_OK) fail(db_.handle(), rc, "bind");
  return *this;
}
Statement& Statement::bind(int i, std::string_view v) {
  if (const int rc = sqlite3_bind_text(st_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT); rc != SQLITE_OK) fail(db_.handle(), rc, "bind");
  return *this;
}
Statement& Statement::bind_null(int i) {
  if (const int rc = sqlite3_bind_null(st_, i); rc != SQLITE_OK) fail(db_.handle(), rc, "bind");
  return *this;
}

bool Statement::step() {
  const int rc = sqlite3_step(st_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  fail(db_.handle(), rc, "step");
}

void Statement::reset() { sqlite3_reset(st_); }
std::int64_t Statement::column_int(int c) const { return sqlite3_column_int64(st_, c); }
double Statement::column_double(int c) const { return sqlite3_column_double(st_, c); }
Statement::Type Statement::column_type(int c) const noexcept {
  switch (sqlite3_column_type(st_, c)) {
    case SQLITE_INTEGER:
      return Type::integer;
    case SQLITE_FLOAT:
      return Type::real;
    case SQLITE_TEXT:
      return Type::text;
    case SQLITE_BLOB:
      return Type::blob;
    default:
      return Type::null;
  }
}
std::string_view Statement::column_view(int c) const {
  const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(st_, c));
  return p ? std::string_view(p, static_cast<std::size_t>(sqlite3_column_bytes(st_, c))) : std::string_view();
}
std::string Statement::column_text(int c) const {
  const auto* p = sqlite3_column_text(st_, c);
  return p ? std::string(reinterpret_cast<const char*>(p), static_cast<std::size_t>(sqlite3_column_bytes(st_, c))) : std::string();
}
bool Statement::column_is_null(int c) const { return sqlite3_column_type(st_, c) == SQLITE_NULL; }

Transaction::Transaction(Database& db, bool immediate) : db_(db) { db_.exec(immediate ? "BEGIN IMMEDIATE" : "BEGIN"); }
Transaction::~Transaction() {
  if (!done_) {
    try {
      db_.exec("ROLLBACK");
    } catch (...) {  // nothing more can be done in a destructor; the connection stays usable
    }
  }
}
void Transaction::commit() {
  db_.exec("COMMIT");
  done_ = true;
}

}  // namespace hystlab::db
