#pragma once
// hystlabd's HTTP/JSON API, its Server-Sent Events stream, /metrics and the page (docs/API.md).
// The HTTP threads read snapshots, live feeds and their own SQLite connections, and send commands
// to the daemon's queue: they never touch a rig and never write a sample.
#include <memory>

#include "hystlab/daemon/daemon.hpp"

namespace hystlab::web {

class HttpApi {
 public:
  // Binds http.bind:http.port (port 0: a free one) and starts serving on its own threads.
  // Throws std::runtime_error when the address cannot be bound.
  HttpApi(daemon::Daemon& daemon, const daemon::HttpConfig& config);
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
