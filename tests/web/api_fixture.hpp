#pragma once
// A real daemon in the test process (its simulated rig is a real hystlab-sim child over Modbus
// TCP, its store a real SQLite file) with its HTTP API on a free loopback port; and a real
// HTTP client (cpp-httplib's) plus a raw socket for requests a client library would tidy up.
#include <arpa/inet.h>
#include <doctest/doctest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "../support/build_paths.hpp"
#include "../support/temp_dir.hpp"
#include "hystlab/daemon/daemon.hpp"
#include "hystlab/daemon/daemon_control.hpp"
#include "hystlab/web/http_api.hpp"

namespace hystlab::test {

using nlohmann::json;
namespace fs = std::filesystem;

struct TempDir {  // the API tests' folder (test_support::TempDir), its path a member as they use it
  test_support::TempDir dir{"api"};
  fs::path path = dir.path();
};

inline json fot_plan(int n, double rate_mm_s = 1.0) {
  return json{{"kind", "fot"},
              {"range_mm", {0, 4}},
              {"subdivisions", n},
              {"ramp_rate_mm_s", rate_mm_s},
              {"dwell_s", 0.05},
              {"sample_rate_hz", 500},
              {"limits", {{"displacement_mm", {-0.5, 4.5}}, {"force_N", 400}, {"rate_mm_s", 20}}}};
}

class LiveDaemon {
 public:
  explicit LiveDaemon(const std::function<void(daemon::DaemonConfig&)>& adjust = {}) {
    setenv("HYSTLAB_SIM", HYSTLAB_SIM.c_str(), 1);
    json cfg{{"rigs", {{{"name", "sim frame"}, {"simulate", {{"time_scale", 20}, {"noise_N", 0.05}}}}}}};
    config = daemon::parse_daemon_config(cfg, dir.path.string());
    config.db_path = (dir.path / "api.db").string();
    config.http.port = 0;
    if (adjust) adjust(config);
    d = std::make_unique<daemon::Daemon>(config);
    control = daemon::make_control(*d);
    http = std::make_unique<web::HttpApi>(*control, config.http);
    thread = std::thread([this] { d->run(stop); });
  }
  ~LiveDaemon() {
    http->stop();
    stop = true;
    thread.join();
  }
  [[nodiscard]] httplib::Client client() const {
    httplib::Client c("127.0.0.1", http->port());
    c.set_read_timeout(10, 0);
    return c;
  }
  // Polls GET path until pred holds on its JSON (or the time is up).
  bool wait_json(const std::string& path, const std::function<bool(const json&)>& pred, double seconds = 60) const {
    auto c = client();
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      if (auto r = c.Get(path.c_str()); r && r->status == 200 && pred(json::parse(r->body))) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }

  TempDir dir;
  daemon::DaemonConfig config;
  std::unique_ptr<daemon::Daemon> d;
  std::unique_ptr<control::DaemonInterface> control;
  std::unique_ptr<web::HttpApi> http;
  std::atomic<bool> stop{false};
  std::thread thread;
};

// A fresh TCP connection to the daemon on loopback.
inline int connect_loopback(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  REQUIRE(connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
  return fd;
}

// One request as written, on a fresh connection; returns the whole answer.
inline std::string raw_request(int port, const std::string& request) {
  const int fd = connect_loopback(port);
  timeval tv{5, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  REQUIRE(write(fd, request.data(), request.size()) == static_cast<ssize_t>(request.size()));
  std::string out;
  char buf[4096];
  for (ssize_t n; (n = read(fd, buf, sizeof buf)) > 0;) out.append(buf, static_cast<std::size_t>(n));
  close(fd);
  return out;
}

}  // namespace hystlab::test
