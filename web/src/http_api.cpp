#include "hystlab/web/http_api.hpp"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <thread>

#include "api_support.hpp"
#include "event_stream.hpp"
#include "read_routes.hpp"
#include "request_guard.hpp"
#include "routes.hpp"
#include "security_headers.hpp"

namespace hystlab::web {
std::string default_dir(const std::string& configured, const std::string& installed_sub, const char* source_tree) {
  if (!configured.empty()) return configured;
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  const auto installed = exe.parent_path().parent_path() / "share" / "hystlab" / "web" / installed_sub;
  if (!ec && std::filesystem::exists(installed / (installed_sub.empty() ? "index.html" : "uPlot.iife.min.js"), ec)) return installed.string();
  return source_tree;
}

struct HttpApi::Impl {
  Impl(control::DaemonInterface& d, const control::HttpConfig& cfg, LabSource lab) : config(cfg), ctx(d, config, d.db_path()) { ctx.lab = std::move(lab); }
  control::HttpConfig config;
  ApiContext ctx;
  httplib::Server server;
  std::thread thread;
  int port = 0;
};

HttpApi::HttpApi(control::DaemonInterface& d, const control::HttpConfig& cfg, LabSource lab) : impl_(std::make_unique<Impl>(d, cfg, std::move(lab))) {
  Impl& m = *impl_;
  httplib::Server& s = m.server;
  s.set_tcp_nodelay(true);  // without it every answer waits ~40 ms for the client's delayed ACK
  // Each open stream holds a thread, and so does each connection still sending its request: 85
  // clients sending headers at 1 byte/s once took all 80 threads, and /api/status went
  // unanswered for 30 s. Threads are cheap beside that; a flood beyond 128 still queues.
  const auto threads = static_cast<std::size_t>(cfg.max_stream_clients) + 128;
  s.new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  s.set_keep_alive_max_count(100);
  s.set_keep_alive_timeout(5);
  s.set_payload_max_length(cfg.max_body_bytes);
  s.set_default_headers(httplib::Headers(security_headers().begin(), security_headers().end()));
  s.set_pre_routing_handler([&m](const httplib::Request& req, httplib::Response& res) { return guard_request(m.ctx, req, res); });
  // Called once the handler (or the error handler) made the answer, before it is written: the
  // request's read connection goes back to the pool (api_support.cpp: reader).
  s.set_post_routing_handler([](const httplib::Request&, httplib::Response&) { release_reader(); });
  s.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (!res.body.empty()) return;  // the handler's own JSON error
    if (res.status == 404)
      send_error(res, 404, "not found", "no such resource: " + req.method + " " + req.path);
    else if (res.status == 413)
      send_error(res, 413, "payload too large", "the request body is larger than http.max_body_bytes");
    else
      send_error(res, res.status, "bad request", "the request could not be served (HTTP " + std::to_string(res.status) + ")");
  });
  add_status_routes(s, m.ctx);
  add_campaign_routes(s, m.ctx);
  // The read endpoints, from this daemon's own file (the lab view serves the same from PostgreSQL).
  add_read_routes(s, "", [&c = m.ctx, xy = make_xy_cache()](const httplib::Request& req, httplib::Response& res, const ReadHandler& h) {
    ReadContext rc{reader(c.db_path), *xy};
    h(req, res, rc);
  });
  add_data_routes(s, m.ctx);
  add_loop_routes(s, m.ctx);
  add_h5_routes(s, m.ctx);
  add_report_routes(s, m.ctx);
  add_stream_route(s, m.ctx);
  const std::string vendor = default_dir(cfg.vendor_root, "vendor/uplot", source_vendor_root()), root = default_dir(cfg.web_root, "", source_web_root());
  if (!s.set_mount_point("/vendor/uplot", vendor))
    spdlog::warn("http: the plotting library is not at '{}' (run 'npm ci' in web/): the page cannot plot", vendor);
  if (std::error_code ec; std::filesystem::is_directory(root, ec))  // unreadable: warned, never thrown
    add_page_route(s, root);                                        // last: a path no API route takes (page_route.cpp: not a mount point)
  else
    spdlog::warn("http: no page at '{}': the API alone is served", root);
  // SO_REUSEADDR only: cpp-httplib's default adds SO_REUSEPORT, and then a second daemon on the
  // same port binds too and the kernel splits requests between them (an abort reached the wrong one).
  s.set_socket_options([](socket_t sock) {
    const int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  m.port = cfg.port == 0 ? s.bind_to_any_port(cfg.bind) : (s.bind_to_port(cfg.bind, cfg.port) ? cfg.port : -1);
  if (m.port <= 0) throw std::runtime_error("http: cannot listen on " + cfg.bind + ":" + std::to_string(cfg.port) + " (in use, or not an address here)");
  m.thread = std::thread([&s] { s.listen_after_bind(); });
  spdlog::info("http: serving the API and the page on http://{}:{}/", cfg.bind, m.port);
}

HttpApi::~HttpApi() { stop(); }

int HttpApi::port() const noexcept { return impl_->port; }

void HttpApi::stop() {
  Impl& m = *impl_;
  m.ctx.stopping = true;
  m.server.stop();
  if (m.thread.joinable()) m.thread.join();
}

}  // namespace hystlab::web
