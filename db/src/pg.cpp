#include "hystlab/db/pg.hpp"

#include <libpq-fe.h>

#include <charconv>
#include <cmath>

namespace hystlab::db {
namespace {
std::string sqlstate_of(const PGresult* r) {
  const char* s = r ? PQresultErrorField(r, PG_DIAG_SQLSTATE) : nullptr;
  return s ? s : "";
}
std::string trimmed(const char* m) {
  std::string s = m ? m : "";
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}
[[noreturn]] void fail_result(PGconn* c, PGresult* r, std::string_view what) {
  std::string msg = trimmed(r ? PQresultErrorMessage(r) : PQerrorMessage(c));
  if (msg.empty()) msg = trimmed(PQerrorMessage(c));
  std::string state = sqlstate_of(r);
  if (state.empty() && PQstatus(c) != CONNECTION_OK) state = "08006";  // the link is gone
  PQclear(r);
  throw PgError("PostgreSQL: " + std::string(what) + ": " + msg, state);
}
}  // namespace

bool conninfo_has_password(std::string_view conninfo) noexcept {
  const bool url = conninfo.starts_with("postgresql://") || conninfo.starts_with("postgres://");
  if (!url) return conninfo.find("password") != std::string_view::npos;
  const std::size_t start = conninfo.find("://") + 3;
  const std::size_t at = conninfo.find('@', start), slash = conninfo.find('/', start), colon = conninfo.find(':', start);
  if (at != std::string_view::npos && (slash == std::string_view::npos || at < slash) && colon < at) return true;
  return conninfo.find("password=") != std::string_view::npos;
}

PgResult::~PgResult() { PQclear(r_); }
int PgResult::rows() const noexcept { return PQntuples(r_); }
bool PgResult::is_null(int row, int col) const noexcept { return PQgetisnull(r_, row, col) != 0; }
std::string PgResult::text(int row, int col) const { return PQgetvalue(r_, row, col); }
std::int64_t PgResult::integer(int row, int col) const {
  const char* v = PQgetvalue(r_, row, col);
  std::int64_t out = 0;
  const auto [end, ec] = std::from_chars(v, v + std::char_traits<char>::length(v), out);
  if (ec != std::errc() || *end != '\0') throw PgError("PostgreSQL: '" + std::string(v) + "' is not a whole number", "");
  return out;
}

PgConnection::PgConnection(const std::string& conninfo, const std::string& password, int connect_timeout_s) {
  const std::string timeout = std::to_string(connect_timeout_s);
  // dbname holding the whole conninfo with expand_dbname: a URL or key=value pairs, and the
  // keywords after it (a password, the timeout, the application's name) added to it.
  // TCP keep-alives and a user timeout before the conninfo (which overrides them): a server host
  // gone mid-COPY fails the call within about 30 s, not the kernel's 15 min of retransmissions.
  const char* keys[] = {"keepalives_idle",
                        "keepalives_interval",
                        "keepalives_count",
                        "tcp_user_timeout",
                        "dbname",
                        "connect_timeout",
                        "application_name",
                        password.empty() ? nullptr : "password",
                        nullptr};
  const char* values[] = {"10", "5", "3", "30000", conninfo.c_str(), timeout.c_str(), "hystlabd", password.empty() ? nullptr : password.c_str(), nullptr};
  c_ = PQconnectdbParams(keys, values, 1);
  if (c_ == nullptr) throw PgError("PostgreSQL: out of memory", "");
  if (PQstatus(c_) != CONNECTION_OK) {
    const std::string msg = trimmed(PQerrorMessage(c_));
    PQfinish(c_);
    c_ = nullptr;
    // libpq gives no SQLSTATE before a session exists: a refused password is told by its text.
    const bool auth = msg.find("password authentication failed") != std::string::npos || msg.find("no password supplied") != std::string::npos;
    throw PgError("PostgreSQL: cannot connect: " + msg, auth ? "28P01" : "08001");
  }
  // Doubles as text read back to the same bits (the default since PostgreSQL 12; said anyway).
  exec("SET extra_float_digits = 3");
  // libpq prints the server's notices on stderr ("schema hystlab already exists, skipping"):
  // warnings and errors only, which reach the caller as PgError anyway.
  exec("SET client_min_messages = warning");
}
PgConnection::~PgConnection() { PQfinish(c_); }

bool PgConnection::ok() const noexcept { return c_ != nullptr && PQstatus(c_) == CONNECTION_OK; }
int PgConnection::server_version() const noexcept { return PQserverVersion(c_); }

void PgConnection::exec(std::string_view sql) {
  PGresult* r = PQexec(c_, std::string(sql).c_str());
  const ExecStatusType s = PQresultStatus(r);
  if (s != PGRES_COMMAND_OK && s != PGRES_TUPLES_OK) fail_result(c_, r, sql.substr(0, 60));
  PQclear(r);
}

PgResult PgConnection::query(std::string_view sql, const std::vector<const char*>& params) {
  PGresult* r = PQexecParams(c_, std::string(sql).c_str(), static_cast<int>(params.size()), nullptr, params.data(), nullptr, nullptr, 0);
  const ExecStatusType s = PQresultStatus(r);
  if (s != PGRES_COMMAND_OK && s != PGRES_TUPLES_OK) fail_result(c_, r, sql.substr(0, 60));
  return PgResult(r);
}

std::int64_t PgConnection::copy_in(std::string_view copy_sql, std::string_view rows) {
  PgCopy copy(*this, copy_sql);
  copy.put(rows);
  return copy.finish();
}

PgCopy::PgCopy(PgConnection& c, std::string_view copy_sql) : c_(c) {
  PGresult* r = PQexec(c_.handle(), std::string(copy_sql).c_str());
  if (PQresultStatus(r) != PGRES_COPY_IN) {
    open_ = false;
    fail_result(c_.handle(), r, copy_sql.substr(0, 60));
  }
  PQclear(r);
}

PgCopy::~PgCopy() {
  if (!open_) return;
  PQputCopyEnd(c_.handle(), "the copy was abandoned");  // the server rolls the COPY back
  while (PGresult* x = PQgetResult(c_.handle())) PQclear(x);
}

void PgCopy::put(std::string_view rows) {
  // In pieces under 1 GiB (libpq's int length); blocking connection: each call sends or fails.
  constexpr std::size_t kPiece = 1U << 20;
  for (std::size_t at = 0; at < rows.size(); at += kPiece) {
    const std::string_view piece = rows.substr(at, kPiece);
    if (PQputCopyData(c_.handle(), piece.data(), static_cast<int>(piece.size())) != 1)
      throw PgError("PostgreSQL: COPY: " + trimmed(PQerrorMessage(c_.handle())), "08006");
  }
}

std::int64_t PgCopy::finish() {
  open_ = false;
  PGconn* c = c_.handle();
  if (PQputCopyEnd(c, nullptr) != 1) throw PgError("PostgreSQL: COPY: " + trimmed(PQerrorMessage(c)), "08006");
  PGresult* r = PQgetResult(c);
  if (PQresultStatus(r) != PGRES_COMMAND_OK) {
    while (PGresult* x = PQgetResult(c)) PQclear(x);
    fail_result(c, r, "COPY");
  }
  const char* n = PQcmdTuples(r);
  const std::int64_t count = n && *n ? std::stoll(n) : 0;
  PQclear(r);
  while (PGresult* x = PQgetResult(c)) PQclear(x);
  return count;
}

PgTransaction::PgTransaction(PgConnection& c) : c_(c) { c_.exec("BEGIN"); }
PgTransaction::~PgTransaction() {
  if (done_ || !c_.ok()) return;
  try {
    c_.exec("ROLLBACK");
  } catch (...) {  // a destructor: the connection is reset by its owner on the next error anyway
  }
}
void PgTransaction::commit() {
  c_.exec("COMMIT");
  done_ = true;
}

void append_copy_text(std::string& out, std::string_view field) {
  for (const char ch : field) {
    switch (ch) {
      case '\\':
        out += "\\\\";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        out += ch;
    }
  }
}

void append_copy_double(std::string& out, double v) {
  if (std::isnan(v)) {
    out += "NaN";
  } else if (std::isinf(v)) {
    out += v > 0 ? "Infinity" : "-Infinity";
  } else {
    char buf[32];
    const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, ec == std::errc() ? end : buf);
  }
}

}  // namespace hystlab::db
