#include "api_support.hpp"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cmath>
#include <memory>

#include "hystlab/daemon/plan.hpp"
#include "hystlab/db/sqlite.hpp"
#include "hystlab/models/formats.hpp"

namespace hystlab::web {

void send_json(httplib::Response& res, const json& body, int status) {
  res.status = status;
  res.set_content(body.dump(-1, ' ', false, json::error_handler_t::replace), "application/json");
}

void send_error(httplib::Response& res, int status, const std::string& error, const std::string& detail) {
  send_json(res, json{{"error", error}, {"detail", detail}}, status);
}

httplib::Server::Handler guarded(std::function<void(const httplib::Request&, httplib::Response&)> f) {
  return [f = std::move(f)](const httplib::Request& req, httplib::Response& res) {
    try {
      f(req, res);
    } catch (const ApiError& e) {
      send_error(res, e.status, e.error, e.what());
    } catch (const daemon::PlanError& e) {
      send_error(res, 400, "invalid plan", e.what());
    } catch (const models::FormatError& e) {
      send_error(res, 400, "invalid document", e.what());
    } catch (const std::invalid_argument& e) {
      send_error(res, 400, "invalid request", e.what());
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
  if (used != s.size() || s.empty() || !std::isfinite(v))
    throw ApiError(400, "invalid parameter", std::string(name) + ": '" + s + "' is not a number");
  if (v < lo || v > hi)
    throw ApiError(400, "invalid parameter", std::string(name) + ": " + s + " is outside [" + json(lo).dump() + ", " + json(hi).dump() + "]");
  return v;
}

json body_object(const httplib::Request& req) {
  json j;
  try {
    j = json::parse(req.body);
  } catch (const json::parse_error& e) {
    throw ApiError(400, "malformed JSON", std::string("the request body is not valid JSON: ") + e.what());
  }
  if (!j.is_object()) throw ApiError(400, "malformed JSON", "the request body must be a JSON object");
  return j;
}

void set_thread_nice(int nice) noexcept {
  (void)setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), nice);
}

db::Store& reader(const std::string& db_path) {
  thread_local std::unique_ptr<db::Store> store;
  if (!store || store->database().path() != db_path) store = std::make_unique<db::Store>(db_path);
  return *store;
}

}  // namespace hystlab::web
