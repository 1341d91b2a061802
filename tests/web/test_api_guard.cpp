// What no request may do: take the daemon down (deep nesting, huge numbers, bad lengths), drive
// it from another site (DNS rebinding, form posts, framing), or hold the threads others need
// (slow senders). And the answers that help a client: errors naming the field, commands with no
// body at all, the read token.
#include <algorithm>
#include <chrono>
#include <thread>
#include <vector>

#include "api_fixture.hpp"
#include "request_guard.hpp"

using namespace hystlab;
using test::json;

namespace {
json error_of(const std::string& raw) {
  const auto body = raw.find("\r\n\r\n");
  return body == std::string::npos ? json() : json::parse(raw.substr(body + 4), nullptr, false);
}
std::string status_line(const std::string& raw) { return raw.substr(0, raw.find("\r\n")); }

std::string request(const std::string& method, const std::string& path, const std::string& headers, const std::string& body = {}) {
  return method + " " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n" + headers +
         (body.empty() ? "" : "Content-Length: " + std::to_string(body.size()) + "\r\n") + "\r\n" + body;
}
}  // namespace

TEST_CASE("bodies that once killed or stalled the daemon are refused at once, and it carries on") {
  test::LiveDaemon live;
  const int port = live.http->port();
  auto c = live.client();
  for (const std::size_t depth : {100'000UL, 10'000UL, 65UL}) {
    CAPTURE(depth);
    const std::string deep = "{\"plan\": " + std::string(depth, '[') + std::string(depth, ']') + "}";
    for (const char* path : {"/api/campaigns", "/api/evaluate", "/api/plans/preview"}) {
      const auto r = c.Post(path, deep, "application/json");
      REQUIRE(r);
      CHECK(r->status == 400);
      CHECK(json::parse(r->body)["detail"].get<std::string>().find("deeper than 64 levels") != std::string::npos);
    }
  }
  // 64 levels is the limit, not a refusal of nesting as such: brackets in strings do not count.
  const std::string ok = "{\"plan\": \"" + std::string(200, '[') + "\"}";
  CHECK(json::parse(c.Post("/api/campaigns", ok, "application/json")->body)["detail"].get<std::string>().find("must be a JSON object") != std::string::npos);
  auto r = c.Post("/api/campaigns", R"({"plan": 1e400})", "application/json");
  REQUIRE(r);
  CHECK(r->status == 400);
  CHECK(r->body.find("out of range") != std::string::npos);
  r = c.Post("/api/campaigns", "{\"plan\": \"\xff\xfe\"}", "application/json");
  REQUIRE(r);
  CHECK(r->status == 400);
  r = c.Post("/api/campaigns", R"({"plan": {"kind": "fot", "range_)", "application/json");  // truncated
  REQUIRE(r);
  CHECK(r->status == 400);
  // Content-Length that is no byte count, or beyond the limit: answered without waiting for it.
  for (const std::string len : {"-5", "1e23", "100000000000000000000000", "abc"}) {
    CAPTURE(len);
    const auto t0 = std::chrono::steady_clock::now();
    const std::string raw = test::raw_request(
        port,
        "POST /api/campaigns HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\nContent-Type: application/json\r\nContent-Length: " + len + "\r\n\r\n{}");
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    CHECK((status_line(raw) == "HTTP/1.1 400 Bad Request" || status_line(raw) == "HTTP/1.1 413 Payload Too Large"));
    CHECK(s < 4.0);  // it was 5 s (cpp-httplib waited that long for the body); a VM's freeze is well under 4
  }
  CHECK(c.Get("/api/status")->status == 200);
}

TEST_CASE("commands need no body: the documented curl -X POST works, and an unknown command is no abort") {
  test::LiveDaemon live;
  const int port = live.http->port();
  auto c = live.client();
  const auto sub = c.Post("/api/campaigns", json{{"plan", test::fot_plan(6, 0.3)}}.dump(), "application/json");
  REQUIRE(sub);
  REQUIRE(sub->status == 201);
  const std::string id = std::to_string(json::parse(sub->body)["id"].get<int>());
  REQUIRE(live.wait_json("/api/campaigns/" + id, [](const json& j) { return j["state"] == "running"; }));
  // An unknown verb: 404 naming it, and the campaign still runs.
  std::string raw = test::raw_request(port, request("POST", "/api/campaigns/" + id + "/explode", ""));
  CHECK(status_line(raw) == "HTTP/1.1 404 Not Found");
  CHECK(error_of(raw)["detail"].get<std::string>().find("'explode'") != std::string::npos);
  // curl -X POST: no Content-Length, no Content-Type, no body.
  raw = test::raw_request(port, request("POST", "/api/campaigns/" + id + "/pause", ""));
  CAPTURE(raw);
  CHECK(status_line(raw) == "HTTP/1.1 202 Accepted");
  CHECK(live.wait_json(
      "/api/campaigns/" + id, [](const json& j) { return j["state"] == "paused"; }, 30));
  raw = test::raw_request(port, request("POST", "/api/campaigns/" + id + "/abort", ""));
  CHECK(status_line(raw) == "HTTP/1.1 202 Accepted");
  CHECK(live.wait_json(
      "/api/campaigns/" + id, [](const json& j) { return j["state"] == "aborted"; }, 30));
  // The rig's e-stop and reset the same way.
  // The e-stop answers once latched and seen in the rig's status word; the reset once the rig
  // reports ready again.
  raw = test::raw_request(port, request("POST", "/api/rigs/sim%20frame/estop", ""));
  CHECK(status_line(raw) == "HTTP/1.1 200 OK");
  CHECK(error_of(raw)["latched"] == true);
  CHECK(error_of(raw)["confirmed"] == true);
  CHECK(live.wait_json(
      "/api/rigs/sim%20frame", [](const json& j) { return j["latched"] == true; }, 30));
  raw = test::raw_request(port, request("POST", "/api/rigs/sim%20frame/reset", ""));
  CHECK(status_line(raw) == "HTTP/1.1 200 OK");
  CHECK(live.wait_json(
      "/api/rigs/sim%20frame", [](const json& j) { return j["latched"] == false; }, 30));
}

TEST_CASE("no other site drives the daemon: DNS rebinding, form posts, framing, NUL paths") {
  test::LiveDaemon live;
  const int port = live.http->port();
  const std::string plan = json{{"plan", test::fot_plan(2)}}.dump();
  // A page from attacker.example whose name now points at 127.0.0.1: same origin to the browser.
  std::string raw = test::raw_request(
      port, "POST /api/campaigns HTTP/1.1\r\nHost: attacker.example:" + std::to_string(port) + "\r\nOrigin: http://attacker.example:" + std::to_string(port) +
                "\r\nContent-Type: application/json\r\nConnection: close\r\nContent-Length: " + std::to_string(plan.size()) + "\r\n\r\n" + plan);
  CHECK(status_line(raw) == "HTTP/1.1 403 Forbidden");
  CHECK(error_of(raw)["detail"].get<std::string>().find("attacker.example") != std::string::npos);
  raw = test::raw_request(port, "GET /api/campaigns HTTP/1.1\r\nHost: attacker.example\r\nConnection: close\r\n\r\n");
  CHECK(status_line(raw) == "HTTP/1.1 403 Forbidden");  // nor read the lab's data
  // A form post (text/plain, no Origin) from any page.
  raw = test::raw_request(port, request("POST", "/api/campaigns", "Content-Type: text/plain\r\n", plan));
  CHECK(status_line(raw) == "HTTP/1.1 415 Unsupported Media Type");
  raw = test::raw_request(port, request("POST", "/api/campaigns/1/abort", "Content-Type: application/x-www-form-urlencoded\r\n", "a=b"));
  CHECK(status_line(raw) == "HTTP/1.1 415 Unsupported Media Type");
  auto c = live.client();
  CHECK(json::parse(c.Get("/api/campaigns")->body).empty());  // nothing was created
  // The allowed names: loopback literals, localhost, a configured name.
  for (const std::string host : {"127.0.0.1", "localhost:8080", "[::1]:8080"}) {
    CAPTURE(host);
    CHECK(status_line(test::raw_request(port, "GET /api/status HTTP/1.1\r\nHost: " + host + "\r\nConnection: close\r\n\r\n")) == "HTTP/1.1 200 OK");
  }
  daemon::HttpConfig named;
  named.allowed_hosts = {"rig-pc.lab.example"};
  CHECK(web::host_allowed(named, "rig-pc.lab.example:8080"));
  CHECK(web::host_allowed(named, "RIG-PC.lab.example"));
  CHECK_FALSE(web::host_allowed(named, "rig-pc.lab.example.attacker.example"));
  // No framing; a NUL in the path is refused.
  const auto r = c.Get("/");
  REQUIRE(r);
  CHECK(r->get_header_value("Content-Security-Policy").find("frame-ancestors 'none'") != std::string::npos);
  CHECK(r->get_header_value("X-Frame-Options") == "DENY");
  raw = test::raw_request(port, "GET /index.html%00.png HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n");
  CHECK(status_line(raw) == "HTTP/1.1 400 Bad Request");
}

TEST_CASE("tokens: at least 16 non-blank characters; a read token keeps the data private") {
  daemon::HttpConfig h;
  h.token = "                 abc";
  CHECK_THROWS_WITH_AS(daemon::check_http_security(h, nullptr), doctest::Contains("non-blank"), daemon::ConfigError);
  h.token = "0123456789abcdef";
  h.read_token = "short";
  CHECK_THROWS_WITH_AS(daemon::check_http_security(h, nullptr), doctest::Contains("http.read_token"), daemon::ConfigError);

  test::LiveDaemon live([](daemon::DaemonConfig& cfg) { cfg.http.read_token = "reader-0123456789abcdef"; });
  auto c = live.client();
  auto r = c.Get("/api/campaigns");
  REQUIRE(r);
  CHECK(r->status == 401);
  CHECK(c.Get("/metrics")->status == 401);
  CHECK(c.Get("/")->status == 200);                                             // the page itself holds no data
  CHECK(c.Get("/api/campaigns?token=reader-0123456789abcdef")->status == 200);  // as an EventSource sends it
  c.set_bearer_token_auth("reader-0123456789abcdef");
  CHECK(c.Get("/api/campaigns")->status == 200);
}

TEST_CASE("slow senders do not hold the threads that status, commands and streams need") {
  test::LiveDaemon live;
  const int port = live.http->port();
  // 85 connections that send a request's headers a byte at a time (measured before: /api/status
  // went unanswered for 30 s).
  std::vector<int> slow;
  for (int k = 0; k < 85; ++k) {
    const int fd = test::connect_loopback(port);
    REQUIRE(write(fd, "G", 1) == 1);
    slow.push_back(fd);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  auto c = live.client();
  c.set_read_timeout(4, 0);
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = c.Get("/api/status");
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  REQUIRE(r);
  CHECK(r->status == 200);
  CHECK(s < 3.0);
  for (const int fd : slow) close(fd);
}

TEST_CASE("bodies are bounded whatever their encoding: chunked and compressed bodies refused unread, header floods refused") {
  test::LiveDaemon live;
  const int port = live.http->port();
  // A chunked body (256 MiB took the daemon to 1.14 GB): refused before a byte of it is read.
  std::string raw = test::raw_request(
      port, request("POST", "/api/campaigns", "Content-Type: application/json\r\nTransfer-Encoding: chunked\r\n") + "10\r\n{\"plan\": {}}    \r\n0\r\n\r\n");
  CAPTURE(raw);
  CHECK(status_line(raw) == "HTTP/1.1 411 Length Required");
  CHECK(error_of(raw)["detail"].get<std::string>().find("Content-Length") != std::string::npos);
  // A gzip body (199 KB inflated to 200 MB): refused.
  raw = test::raw_request(port, request("POST", "/api/campaigns", "Content-Type: application/json\r\nContent-Encoding: gzip\r\n", "\x1f\x8b junk"));
  CHECK(status_line(raw) == "HTTP/1.1 415 Unsupported Media Type");
  CHECK(error_of(raw)["detail"].get<std::string>().find("gzip") != std::string::npos);
  // 2,000 header fields: refused with the count.
  std::string many;
  for (int k = 0; k < 2000; ++k) many += "X-Filler-" + std::to_string(k) + ": 1\r\n";
  raw = test::raw_request(port, request("GET", "/api/status", many));
  CHECK(status_line(raw).find("431") != std::string::npos);
  // And the daemon carries on.
  auto c = live.client();
  const auto r = c.Get("/api/status");
  REQUIRE(r);
  CHECK(r->status == 200);
}
