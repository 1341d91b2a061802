#pragma once
// hystlabd's HTTP/JSON API, its Server-Sent Events stream, /metrics and the page (docs/API.md).
// The HTTP threads reach the daemon only through its interface (snapshots, live samples, plans and
// commands) and read the database through their own connections: they never touch a rig and
// never write a sample.
#include <functional>
#include <memory>

#include "hystlab/control/daemon_interface.hpp"
#include "hystlab/control/http_config.hpp"

namespace hystlab::web {

class HttpApi {
 public:
  // Binds http.bind:http.port (port 0: a free one) and starts serving on its own threads.
  // Throws std::runtime_error when the address cannot be bound.
  // lab: what the daemon shares with its lab (replication, MQTT), read for /api/status and
  // /metrics from the HTTP threads; empty: no lab section.
  using LabSource = std::function<control::LabCounters()>;
  HttpApi(control::DaemonInterface& daemon, const control::HttpConfig& config, LabSource lab = {});
  ~HttpApi();  // stop()
  HttpApi(const HttpApi&) = delete;
  HttpApi& operator=(const HttpApi&) = delete;

  [[nodiscard]] int port() const noexcept;
  void stop();  // ends streams and closes the listener; idempotent

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hystlab::web
