#pragma once
// The HTTP/JSON API's settings ("http" in hystlab.json). Binding anywhere but loopback needs a
// token, which every request that changes state must carry; the daemon refuses to start otherwise.
#include <cstddef>
#include <string>
#include <vector>

namespace hystlab::control {

struct HttpConfig {
  bool enabled = true;
  std::string bind = "127.0.0.1";
  int port = 8080;
  std::string token;                       // from the config, or $HYSTLAB_TOKEN: needed by every request that changes state
  std::string read_token;                  // when set, reads of the API need it (or token) too: for labs whose data is not public
  std::vector<std::string> allowed_hosts;  // Host names served besides IP literals, localhost and this machine's name
  std::string web_root;                    // the page; empty: the one built in (web/static of the source tree, or installed)
  std::string vendor_root;                 // the plotting library's files (npm's uplot/dist)
  int max_stream_clients = 64;             // SSE subscribers; each holds one pool thread
  std::size_t max_body_bytes = 8U << 20;
};

}  // namespace hystlab::control
