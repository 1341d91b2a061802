#include "hystlab/web/lab_view.hpp"

#include <httplib.h>
#include <spdlog/spdlog.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string_view>
#include <thread>

#include "api_support.hpp"
#include "hystlab/db/lab_reads.hpp"
#include "hystlab/db/pg_reads.hpp"
#include "lab_view_json.hpp"
#include "read_routes.hpp"
#include "report_svg.hpp"
#include "request_guard.hpp"
#include "routes.hpp"
#include "security_headers.hpp"

namespace hystlab::web {
using nlohmann::json;

struct LabView::Impl {
  Impl(const control::HttpConfig& h, const lab::LabConfig& l, LiveSource s) : http(h), lab(l), live(std::move(s)) {}
  control::HttpConfig http;
  lab::LabConfig lab;
  LiveSource live;
  httplib::Server server;
  std::thread thread;
  int port = 0;
  // Connections to the lab's database, one per request at a time (libpq's connection is not to be
  // shared between threads at once), kept for the next: a request over a long run (its loop, its
  // score) never holds the others up. pg_mu guards the idle ones and the status, never a query.
  static constexpr std::size_t kIdle = 4;
  std::mutex pg_mu;
  std::vector<std::unique_ptr<db::PgConnection>> idle;
  bool connected = false;
  std::string pg_error;

  void with_lab(httplib::Response& res, const std::function<void(db::LabReads&)>& f) {
    with_pg(res, [&](db::PgConnection& c) {
      db::LabReads reads(c);
      f(reads);
    });
  }
  std::unique_ptr<db::PgConnection> take() {
    {
      const std::lock_guard lock(pg_mu);
      while (!idle.empty()) {
        auto c = std::move(idle.back());
        idle.pop_back();
        if (c->ok()) return c;
      }
    }
    auto c = std::make_unique<db::PgConnection>(lab.postgres.conninfo, lab.postgres.password);
    // A view only reads, and a slow query is cut off (504) rather than left to run.
    c->exec("SET default_transaction_read_only = on");
    c->exec("SET statement_timeout = '20s'");
    return c;
  }
  void give_back(std::unique_ptr<db::PgConnection> c, const std::string& error) {
    const std::lock_guard lock(pg_mu);
    connected = error.empty() || (c && c->ok());
    if (error.empty() || !connected) pg_error = error;
    if (c && c->ok() && idle.size() < kIdle) idle.push_back(std::move(c));
  }
  // f(a connection of its own), connecting first when none is idle. A server lost (or never
  // reached) is a 503 naming it, and the next request connects again; a statement cut off by the
  // timeout is a 504; any other error of the database, a 500 with its words.
  void with_pg(httplib::Response& res, const std::function<void(db::PgConnection&)>& f) {
    std::unique_ptr<db::PgConnection> c;
    try {
      c = take();
      f(*c);
      give_back(std::move(c), "");
    } catch (const db::PgError& e) {
      const bool lost = !c || !c->ok() || e.sqlstate.starts_with("08");
      give_back(std::move(c), e.what());
      if (lost) return send_error(res, 503, "lab database unavailable", e.what());
      if (e.sqlstate == "57014") return send_error(res, 504, "lab database too slow", e.what());
      send_error(res, 500, "lab database error", e.what());
    }
  }
  json pg_status() {
    const std::lock_guard lock(pg_mu);
    return {{"connected", connected}, {"error", pg_error.empty() ? json(nullptr) : json(pg_error)}};
  }
};

namespace {
std::string file_text(const std::string& path) { return file_bytes(path).value_or(std::string()); }
db::LabFilter filter_of(const httplib::Request& req, const std::string& lab) {
  return {lab, req.get_param_value("daemon"), req.get_param_value("specimen"), req.get_param_value("kind"),
          static_cast<int>(query_number(req, "limit", 200, 1, 5000))};
}

// A daemon's read endpoints at /daemons/NAME/api/..., answered from its rows in the lab database
// with the rig daemon's own handlers (read_routes.hpp).
void add_daemon_routes(httplib::Server& s, LabView::Impl& m) {
  add_read_routes(s, "/daemons/([^/]+)", [&m](const httplib::Request& req, httplib::Response& res, const ReadHandler& h) {
    const std::string daemon = req.matches[1].str();
    m.with_pg(res, [&](db::PgConnection& pg) {
      const auto id = db::PgReads::daemon_id(pg, m.lab.name, daemon);
      if (!id) return send_error(res, 404, "not found", "no daemon '" + daemon + "' in lab " + m.lab.name);
      db::PgReads reads(pg, *id);
      // A cache for this request only: a run still replicating must be read again next time.
      const auto xy = make_xy_cache();
      ReadContext rc{reads, *xy};
      h(req, res, rc);
    });
  });
}

// The rig's own page, showing one daemon's records read-only (web/static/api.js: the meta says
// where its API is); its name escaped, as it goes into HTML.
std::string archive_page(const std::string& index, const std::string& daemon) {
  const std::string name = report::esc(daemon);
  std::string base;  // the path segment as the browser sent it, percent-encoded where needed
  for (const char c : daemon) {
    const auto ch = static_cast<unsigned char>(c);
    if (std::isalnum(ch) || ch == '-' || ch == '_' || ch == '.' || ch == '~') {
      base += static_cast<char>(ch);
    } else {
      constexpr const char* kHex = "0123456789ABCDEF";
      base += '%', base += kHex[ch >> 4], base += kHex[ch & 15];
    }
  }
  const std::string meta = "<meta name=\"hystlab-base\" content=\"/daemons/" + base + "\" data-daemon=\"" + name + "\">\n";
  std::string out = index;
  const std::size_t at = out.find("<head>");
  return at == std::string::npos ? out : out.insert(at + 6, "\n" + meta);
}

void add_lab_routes(httplib::Server& s, LabView::Impl& m) {
  s.Get("/api/status", guarded([&m](const httplib::Request&, httplib::Response& res) {
          const json live = m.live ? m.live() : json::object();
          send_json(res, {{"name", "hystlabd"},
                          {"mode", "lab view"},
                          {"version", HYSTLAB_VERSION},
                          {"lab", {{"name", m.lab.name}, {"postgresql", m.pg_status()}, {"mqtt", mqtt_status(live)}}}});
        }));
  s.Get("/api/lab", guarded([&m](const httplib::Request&, httplib::Response& res) {
          const json live = m.live ? m.live() : json::object();
          m.with_lab(res, [&](db::LabReads& r) { send_json(res, lab_overview_json(m.lab.name, r.daemons(m.lab.name), r.rigs(m.lab.name), live)); });
        }));
  s.Get("/api/lab/campaigns", guarded([&m](const httplib::Request& req, httplib::Response& res) {
          const db::LabFilter f = filter_of(req, m.lab.name);
          m.with_lab(res, [&](db::LabReads& r) { send_json(res, campaigns_json(r.campaigns(f))); });
        }));
  s.Get(R"(/api/lab/campaigns/([^/]+)/(\d+))", guarded([&m](const httplib::Request& req, httplib::Response& res) {
          const std::string daemon = req.matches[1].str();
          const std::int64_t id = path_id(req, 2);
          m.with_lab(res, [&](db::LabReads& r) {
            const auto c = r.campaign(daemon, id, m.lab.name);
            if (!c || c->lab != m.lab.name)
              return send_error(res, 404, "not found", "no campaign " + std::to_string(id) + " of daemon '" + daemon + "' in lab " + m.lab.name);
            send_json(res, campaign_json(*c, r.runs(c->daemon_id, id), r.events(c->daemon_id, id), r.campaign_tables(c->daemon_id, id)));
          });
        }));
  s.Get(R"(/api/lab/runs/([^/]+)/(\d+)/overview)", guarded([&m](const httplib::Request& req, httplib::Response& res) {
          const std::string daemon = req.matches[1].str();
          const std::int64_t run = path_id(req, 2);
          const int buckets = static_cast<int>(query_number(req, "buckets", 600, 10, 5000));
          const bool shaker = req.get_param_value("shaker") == "1";
          m.with_lab(res, [&](db::LabReads& r) {
            for (const db::LabDaemon& d : r.daemons(m.lab.name))
              if (d.name == daemon) return send_json(res, overview_json(r.overview(d.id, run, shaker, buckets)));
            send_error(res, 404, "not found", "no daemon '" + daemon + "' in lab " + m.lab.name);
          });
        }));
  s.Get("/api/lab/tables", guarded([&m](const httplib::Request& req, httplib::Response& res) {
          const db::LabFilter f = filter_of(req, m.lab.name);
          m.with_lab(res, [&](db::LabReads& r) { send_json(res, tables_json(r.tables(f))); });
        }));
}
}  // namespace

LabView::LabView(const control::HttpConfig& http, const lab::LabConfig& lab, LiveSource live) : impl_(std::make_unique<Impl>(http, lab, std::move(live))) {
  Impl& m = *impl_;
  httplib::Server& s = m.server;
  s.set_tcp_nodelay(true);
  s.set_default_headers(httplib::Headers(security_headers().begin(), security_headers().end()));
  // Read-only by design: only GET (and HEAD); a host this view does not serve is refused, as on a
  // rig's own daemon (a page of another site reaching it through DNS rebinding).
  s.set_pre_routing_handler([&m](const httplib::Request& req, httplib::Response& res) {
    if (!host_allowed(m.http, req.get_header_value("Host"))) {
      send_error(res, 403, "unknown host", "Host '" + req.get_header_value("Host") + "' is not a name this view serves (add it to http.allowed_hosts)");
      return httplib::Server::HandlerResponse::Handled;
    }
    if (req.method != "GET" && req.method != "HEAD") {
      send_error(res, 405, "read-only", "the lab view moves nothing: commands go to the rig's own daemon (its link on the page)");
      return httplib::Server::HandlerResponse::Handled;
    }
    return check_read(m.http, req, res);  // http.read_token, as a rig's own daemon
  });
  s.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
    if (res.body.empty() && res.status == 404) send_error(res, 404, "not found", "no such resource: " + req.method + " " + req.path);
  });
  add_lab_routes(s, m);
  add_daemon_routes(s, m);
  const std::string root = default_dir(http.web_root, "", source_web_root()), vendor = default_dir(http.vendor_root, "vendor/uplot", source_vendor_root());
  s.set_mount_point("/vendor/uplot", vendor);
  // The lab's page at "/"; the rig page's scripts and style beside it (a daemon's records are shown
  // on the rig's own page, /daemons/NAME/). Files by name, so that "/" stays the lab's page.
  std::error_code ec;  // a folder that is not there serves nothing (the page then says so), never throws
  for (const auto& entry : std::filesystem::directory_iterator(root, ec)) {
    const std::string name = entry.path().filename().string();
    const bool js = name.ends_with(".js"), css = name.ends_with(".css"), svg = name.ends_with(".svg");
    if (!js && !css && !svg) continue;
    const char* type = js ? "text/javascript" : css ? "text/css" : "image/svg+xml";
    std::string pattern = "/";  // the route is a regex: its name's dots (and any other special) as themselves
    for (const char ch : name) pattern += std::string_view(".^$|?*+()[]{}\\").find(ch) != std::string_view::npos ? std::string("\\") + ch : std::string(1, ch);
    s.Get(pattern, [path = entry.path().string(), type](const httplib::Request&, httplib::Response& res) { res.set_content(file_text(path), type); });
  }
  s.Get("/", [root](const httplib::Request&, httplib::Response& res) { res.set_content(file_text(root + "/lab.html"), "text/html; charset=utf-8"); });
  s.Get("/daemons/([^/]+)/", [root](const httplib::Request& req, httplib::Response& res) {
    res.set_content(archive_page(file_text(root + "/index.html"), req.matches[1].str()), "text/html; charset=utf-8");
  });
  m.port = http.port == 0 ? s.bind_to_any_port(http.bind) : (s.bind_to_port(http.bind, http.port) ? http.port : -1);
  if (m.port <= 0) throw std::runtime_error("http: cannot listen on " + http.bind + ":" + std::to_string(http.port) + " (in use, or not an address here)");
  m.thread = std::thread([&s] { s.listen_after_bind(); });
}

LabView::~LabView() { stop(); }
int LabView::port() const noexcept { return impl_->port; }
void LabView::stop() {
  impl_->server.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

}  // namespace hystlab::web
