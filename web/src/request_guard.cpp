#include "request_guard.hpp"

#include <arpa/inet.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>

namespace hystlab::web {
namespace {
using HR = httplib::Server::HandlerResponse;
// A browser sends about 15; 100 is what nginx's default buffers hold.
constexpr std::size_t kMaxHeaders = 100;

bool changes_state(const std::string& method) { return method != "GET" && method != "HEAD" && method != "OPTIONS"; }

// Equal-time comparison: the token must not leak through timing.
bool same_secret(const std::string& a, const std::string& b) {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (std::size_t k = 0; k < a.size(); ++k) diff |= static_cast<unsigned char>(a[k] ^ (k < b.size() ? b[k] : 0));
  return diff == 0;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return s;
}

// The token the request carries: Authorization: Bearer, X-Hystlab-Token, or ?token= (the only
// way an EventSource can send one).
std::string given_token(const httplib::Request& req) {
  const std::string auth = req.get_header_value("Authorization");
  if (auth.rfind("Bearer ", 0) == 0) return auth.substr(7);
  if (req.has_header("X-Hystlab-Token")) return req.get_header_value("X-Hystlab-Token");
  return req.has_param("token") ? req.get_param_value("token") : std::string();
}

bool is_json_type(const std::string& content_type) {
  const std::string t = lower(content_type.substr(0, content_type.find(';')));
  return t == "application/json";
}

HR refuse(httplib::Response& res, int status, const std::string& error, const std::string& detail) {
  send_error(res, status, error, detail);
  return HR::Handled;
}

// Content-Length must be digits and not far beyond http.max_body_bytes; otherwise answered at
// once (cpp-httplib read -5 as 2^64 - 5, and 1e23 as 1, and waited 5 s for the body).
bool bad_length(const ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  if (!req.has_header("Content-Length")) return false;
  const std::string v = req.get_header_value("Content-Length");
  const bool digits = !v.empty() && v.size() <= 19 && std::all_of(v.begin(), v.end(), [](unsigned char ch) { return std::isdigit(ch) != 0; });
  // Somewhat over the limit: cpp-httplib reads and drops the body, then answers 413 (a client
  // still sending gets its answer, not a reset). Far over it, nobody is sending that much.
  if (digits && std::stoull(v) <= 2 * c.config.max_body_bytes) return false;
  // The body is never read: the client is told the connection ends here.
  res.set_header("Connection", "close");
  if (!digits)
    send_error(res, 400, "bad request", "Content-Length '" + v + "' is not a byte count");
  else
    send_error(res, 413, "payload too large", "the request body (" + v + " bytes) is larger than http.max_body_bytes");
  return true;
}

// cpp-httplib 0.11 (Debian's shared library) answers "Accept-Encoding: br" with Brotli at the
// encoder's default quality (11, its slowest): a 280 KB samples answer took 3.7-6.0 s here
// against 0.05-0.38 s uncompressed (stop 20's bench_page; curl --compressed), and every browser
// asks for br, so the page waited seconds for each plot and the long loop timed out. Without br
// in the request, the library picks gzip (zlib's default level): milliseconds.
void drop_brotli(const httplib::Request& req) {
  // The library's own non-const Request, handed to this hook as const (as in dispatch_bodiless).
  auto& headers = const_cast<httplib::Headers&>(req.headers);
  const auto it = headers.find("Accept-Encoding");
  if (it == headers.end()) return;
  std::string kept;
  std::size_t from = 0;
  while (from <= it->second.size()) {
    const std::size_t comma = std::min(it->second.find(',', from), it->second.size());
    const std::string token = it->second.substr(from, comma - from);
    const std::size_t b = token.find_first_not_of(' '), e = token.find_first_of(" ;");
    const std::string name = b == std::string::npos ? "" : lower(token.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (!name.empty() && name != "br") kept += (kept.empty() ? "" : ", ") + token.substr(b);
    from = comma + 1;
  }
  it->second = kept.empty() ? "identity" : kept;
}

HR dispatch_bodiless(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  for (const auto& [pattern, handler] : c.post_routes) {
    // The Request is cpp-httplib's own non-const object, handed to this hook as const; the
    // route's handler reads its captures from matches, as when cpp-httplib routes it.
    auto& r = const_cast<httplib::Request&>(req);
    if (std::regex_match(r.path, r.matches, pattern)) {
      handler(req, res);
      return HR::Handled;
    }
  }
  return refuse(res, 404, "not found", "no such resource: POST " + req.path);
}

HR check_write(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  if (req.has_header("Origin")) {
    const std::string origin = req.get_header_value("Origin"), host = req.get_header_value("Host");
    if (origin != "http://" + host) return refuse(res, 403, "cross-origin request refused", "Origin '" + origin + "' is not this server (" + host + ")");
  }
  const std::string given = given_token(req);
  const bool has_token = !c.config.token.empty() && same_secret(given, c.config.token);
  if (!c.config.token.empty() && !has_token) {
    res.set_header("WWW-Authenticate", "Bearer realm=\"hystlabd\"");
    return refuse(res, 401, "unauthorized",
                  given.empty() ? "this request changes state: send the daemon's token (Authorization: Bearer ...)" : "the token does not match");
  }
  if (bad_length(c, req, res)) return HR::Handled;
  // The 8 MiB limit holds for a declared length only: cpp-httplib 0.11 reads a chunked body to its
  // end whatever its size (256 MiB took the daemon to 1.14 GB) and inflates a gzip body before any
  // handler sees it (199 KB became 200 MB). Every client of this API sends a length, and JSON as is.
  if (req.has_header("Transfer-Encoding")) {
    res.set_header("Connection", "close");
    return refuse(res, 411, "length required",
                  "send the request body with a Content-Length, not Transfer-Encoding: " + req.get_header_value("Transfer-Encoding"));
  }
  if (req.has_header("Content-Encoding") && lower(req.get_header_value("Content-Encoding")) != "identity") {
    res.set_header("Connection", "close");
    return refuse(res, 415, "unsupported media type", "send the request body as is, not Content-Encoding: " + req.get_header_value("Content-Encoding"));
  }
  const bool has_body = req.has_header("Content-Length") && req.get_header_value("Content-Length").find_first_not_of('0') != std::string::npos;
  // A browser's form (text/plain, urlencoded, multipart) can be posted from any site, with no
  // Origin in some browsers: a change of state is JSON, or no body at all, or carries the token.
  // An empty body of any type is no body (curl -d '' sends it as a form): a command works as the
  // docs write it.
  if (!has_token && has_body && !(req.has_header("Content-Type") && is_json_type(req.get_header_value("Content-Type"))))
    return refuse(
        res, 415, "unsupported media type",
        "a request that changes state sends JSON (Content-Type: application/json) or no body at all, not '" + req.get_header_value("Content-Type") + "'");
  if (!req.has_header("Content-Length")) return dispatch_bodiless(c, req, res);
  return HR::Unhandled;
}
}  // namespace

bool host_allowed(const control::HttpConfig& config, const std::string& host_header) {
  if (host_header.empty()) return true;
  if (host_header.front() == '[') return host_header.find(']') != std::string::npos;  // an IPv6 literal
  const std::string name = lower(host_header.substr(0, host_header.rfind(':')));
  in_addr v4{};
  if (inet_pton(AF_INET, name.c_str(), &v4) == 1 || name == "localhost" || name == lower(config.bind)) return true;
  char self[256] = {};
  if (gethostname(self, sizeof self - 1) == 0) {
    const std::string me = lower(self);
    if (name == me || name == me.substr(0, me.find('.'))) return true;
  }
  return std::any_of(config.allowed_hosts.begin(), config.allowed_hosts.end(), [&](const std::string& h) { return lower(h) == name; });
}

HR guard_request(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  // HTTP threads yield to acquisition: each lowers its own priority once (no privilege needed).
  static thread_local const bool lowered = (set_thread_nice(kRequestNice), true);
  (void)lowered;
  c.requests.fetch_add(1, std::memory_order_relaxed);
  drop_brotli(req);
  if (req.path.find('\0') != std::string::npos) return refuse(res, 400, "bad request", "the path contains a NUL byte");
  if (req.headers.size() > kMaxHeaders) {
    res.set_header("Connection", "close");
    return refuse(res, 431, "request header fields too large",
                  "the request has " + std::to_string(req.headers.size()) + " header fields; at most " + std::to_string(kMaxHeaders) + " are read");
  }
  // DNS rebinding: a page from attacker.example, its name re-pointed at 127.0.0.1, reaches this
  // port as "same origin"; its Host header still says attacker.example.
  if (!host_allowed(c.config, req.get_header_value("Host")))
    return refuse(res, 403, "unknown host", "Host '" + req.get_header_value("Host") + "' is not a name this daemon serves (add it to http.allowed_hosts)");
  return changes_state(req.method) ? check_write(c, req, res) : check_read(c.config, req, res);
}

void post_route(httplib::Server& s, ApiContext& c, const std::string& pattern, httplib::Server::Handler h) {
  c.post_routes.emplace_back(std::regex(pattern), h);
  s.Post(pattern, std::move(h));
}

httplib::Server::HandlerResponse check_read(const control::HttpConfig& config, const httplib::Request& req, httplib::Response& res) {
  const bool data = req.path.rfind("/api/", 0) == 0 || req.path == "/metrics";
  if (config.read_token.empty() || !data) return HR::Unhandled;
  const std::string given = given_token(req);
  if (same_secret(given, config.read_token) || (!config.token.empty() && same_secret(given, config.token))) return HR::Unhandled;
  res.set_header("WWW-Authenticate", "Bearer realm=\"hystlabd\"");
  return refuse(res, 401, "unauthorized", "this daemon's data needs its read token (http.read_token): Authorization: Bearer ...");
}

}  // namespace hystlab::web
