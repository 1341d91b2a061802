#include "api_support.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <memory>
#include <mutex>
#include <sstream>
#include <vector>

#include "hystlab/db/sqlite.hpp"
#include "hystlab/models/formats.hpp"

namespace hystlab::web {

void send_json(httplib::Response& res, const json& body, int status) {
  res.status = status;
  res.set_content(body.dump(-1, ' ', false, json::error_handler_t::replace), "application/json");
}

void send_error(httplib::Response& res, int status, const std::string& error, const std::string& detail, const std::string& field) {
  json body{{"error", error}, {"detail", detail}};
  if (!field.empty()) body["field"] = field;
  send_json(res, body, status);
}

void send_outcome(httplib::Response& res, json head, const control::CommandOutcome& o) {
  using R = control::CommandOutcome::Result;
  head["result"] = control::to_string(o.result);
  head["accepted"] = o.result == R::done || o.result == R::pending;
  head["latched"] = o.latched;
  head["confirmed"] = o.confirmed;
  head["state"] = o.state;
  head["reason"] = o.reason;
  head["waited_ms"] = std::round(o.waited_s * 1e4) / 10;
  int status = 200;
  if (o.result == R::pending) status = 202;
  if (o.result == R::conflict || o.result == R::refused) status = 409, head["error"] = "conflict", head["detail"] = o.reason;
  if (o.result == R::unreachable) status = 503, head["error"] = "rig unreachable", head["detail"] = o.reason;
  send_json(res, head, status);
}

namespace {
// "rig: no rig named 'x'" names its field before the colon ("rig", "plan.kind").
std::string field_of(const std::string& text) {
  const auto colon = text.find(": ");
  if (colon == std::string::npos || colon == 0 || colon > 40) return {};
  for (std::size_t k = 0; k < colon; ++k)
    if (!(std::isalnum(static_cast<unsigned char>(text[k])) || text[k] == '_' || text[k] == '.' || text[k] == '[' || text[k] == ']')) return {};
  return text.substr(0, colon);
}
}  // namespace

httplib::Server::Handler guarded(std::function<void(const httplib::Request&, httplib::Response&)> f) {
  return [f = std::move(f)](const httplib::Request& req, httplib::Response& res) {
    try {
      f(req, res);
    } catch (const ApiError& e) {
      send_error(res, e.status, e.error, e.what(), e.field);
    } catch (const control::PlanError& e) {
      send_error(res, 400, "invalid plan", e.what(), e.field.empty() ? std::string() : "plan." + e.field);
    } catch (const models::FormatError& e) {
      send_error(res, 400, "invalid document", e.what());
    } catch (const std::invalid_argument& e) {
      send_error(res, 400, "invalid request", e.what(), field_of(e.what()));
    } catch (const db::DbError& e) {
      send_error(res, 500, "storage error", e.what());
    } catch (const std::exception& e) {
      send_error(res, 500, "internal error", e.what());
    }
  };
}

std::int64_t path_id(const httplib::Request& req, std::size_t group) {
  const std::string s = req.matches[group].str();
  if (s.empty() || s.size() > 15) throw ApiError(404, "not found", "no such id '" + s + "'");
  return std::stoll(s);  // the route's pattern admits digits only
}

double query_number(const httplib::Request& req, const char* name, double def, double lo, double hi) {
  if (!req.has_param(name)) return def;
  const std::string s = req.get_param_value(name);
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != s.size() || s.empty() || !std::isfinite(v)) throw ApiError(400, "invalid parameter", std::string(name) + ": '" + s + "' is not a number");
  if (v < lo || v > hi)
    throw ApiError(400, "invalid parameter", std::string(name) + ": " + s + " is outside [" + json(lo).dump() + ", " + json(hi).dump() + "]");
  return v;
}

json body_object(const httplib::Request& req, bool allow_empty) { return parse_body(req.body, allow_empty); }

void set_thread_nice(int nice) noexcept { (void)setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), nice); }

namespace {
// The read connections kept between requests. One per HTTP thread, as before, kept every thread's
// connection and its page cache (up to 2 MiB, filled by the raw rows of a running run's overview):
// with the pool's 190 threads taking requests in turn, the page's GET /api/runs/ID/samples every
// 2 s grew the daemon by 1,073 bytes per sample acquired (issue 40; 199 threads, 15 malloc arenas
// of ~5 MiB each seen in /proc/PID/smaps). A request now takes a connection from here and gives it
// back when its answer is written (release_reader): at most kKeptReaders stay open, whatever the
// number of threads; a request beyond them opens its own and closes it after.
constexpr std::size_t kKeptReaders = 4;
struct ReaderPool {
  std::mutex mu;
  std::vector<std::unique_ptr<db::Store>> idle;
};
ReaderPool& pool() {
  static ReaderPool p;
  return p;
}
thread_local std::unique_ptr<db::Store> t_reader;
}  // namespace

db::Reads& reader(const std::string& db_path) {
  if (t_reader && t_reader->database().path() == db_path) return *t_reader;
  release_reader();
  {
    ReaderPool& p = pool();
    std::lock_guard lk(p.mu);
    for (auto it = p.idle.begin(); it != p.idle.end(); ++it)
      if ((*it)->database().path() == db_path) {
        t_reader = std::move(*it);
        p.idle.erase(it);
        return *t_reader;
      }
  }
  t_reader = std::make_unique<db::Store>(db_path);
  return *t_reader;
}

void release_reader() noexcept {
  if (!t_reader) return;
  std::unique_ptr<db::Store> store = std::move(t_reader);
  ReaderPool& p = pool();
  std::lock_guard lk(p.mu);
  if (p.idle.size() < kKeptReaders) {
    try {
      p.idle.push_back(std::move(store));
    } catch (...) {  // no room to keep it: closed below, as a surplus one is
    }
  }
}  // a connection not kept closes here, after the lock is let go (the guard goes first)

std::optional<std::string> file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace hystlab::web
