#pragma once
// Small helpers shared by the API's route files: JSON answers, errors as
// {"error", "detail"} with the right status, argument parsing, and each HTTP thread's own
// read connection to the store.
#include <httplib.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "hystlab/control/daemon_interface.hpp"
#include "hystlab/control/http_config.hpp"
#include "hystlab/db/store.hpp"
#include "request_body.hpp"

namespace hystlab::web {

using nlohmann::json;

void send_json(httplib::Response& res, const json& body, int status = 200);
// field: the request's field at fault ("plan.ramp_rate_mm_s"), for a form to mark; empty: none.
void send_error(httplib::Response& res, int status, const std::string& error, const std::string& detail, const std::string& field = {});
// An operator command's answer: 200 done, 202 pending (taken, not yet confirmed), 409 conflict or
// refused (with the reason), 503 unreachable (an e-stop is latched here all the same). The body
// carries the outcome whatever the status, with error and detail when it is not 2xx.
void send_outcome(httplib::Response& res, nlohmann::json head, const control::CommandOutcome& o);

// Wraps a handler: every exception becomes one JSON error (400 for bad input, 500 otherwise).
httplib::Server::Handler guarded(std::function<void(const httplib::Request&, httplib::Response&)> f);

// The id captured by the route's first group; 404 when it is out of range.
std::int64_t path_id(const httplib::Request& req, std::size_t group = 1);
// A query parameter as a number in [lo, hi]; def when absent; 400 naming it otherwise.
double query_number(const httplib::Request& req, const char* name, double def, double lo, double hi);
// The body as a JSON object (parse_body); an empty body as {} when allow_empty.
json body_object(const httplib::Request& req, bool allow_empty = false);

// The page's folder: the configured one; else the installed one beside the executable
// (<bindir>/../share/hystlab/web/<sub>); else the source tree's.
std::string default_dir(const std::string& configured, const std::string& installed_sub, const char* source_tree);
// The source tree's page and plotting-library folders (web/src/source_roots.cpp, the one object
// that names the clone's folder: a compiler cache serves every other in a clone elsewhere).
const char* source_web_root() noexcept;
const char* source_vendor_root() noexcept;
// A page file's bytes; nullopt when it cannot be opened (the daemon's and the lab view's pages).
std::optional<std::string> file_bytes(const std::string& path);

// The read connection this thread holds for its request (WAL: never blocks the writer), taken
// from a small shared pool on first use. release_reader() gives it back: the server's post-routing
// handler calls it once a request's answer is made, and a stream after each read.
db::Reads& reader(const std::string& db_path);
void release_reader() noexcept;

// HTTP threads yield to acquisition and to the rig's simulator: requests run at nice 5, and a
// thread streaming events at nice 19 and off the acquisition's CPU (its work is small and its
// latency budget large; its system calls on that CPU would delay the acquisition's wake-ups).
constexpr int kRequestNice = 5, kStreamNice = 19;
void set_thread_nice(int nice) noexcept;  // this thread only; best effort (raising back needs privilege)

// Shared by the route files.
struct ApiContext {
  ApiContext(control::DaemonInterface& d, const control::HttpConfig& c, std::string db) : daemon(d), config(c), db_path(std::move(db)) {}
  control::DaemonInterface& daemon;
  const control::HttpConfig& config;
  std::string db_path;
  std::atomic<int> stream_clients{0};
  std::atomic<bool> stopping{false};
  std::atomic<std::uint64_t> requests{0};
  std::function<control::LabCounters()> lab;  // empty: no lab section (HttpApi::LabSource)
  // Every POST route, for requests with no body at all (request_guard.hpp); filled before listening.
  std::vector<std::pair<std::regex, httplib::Server::Handler>> post_routes;
};

}  // namespace hystlab::web
