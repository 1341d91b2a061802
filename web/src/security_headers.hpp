#pragma once
// The headers every answer of hystlabd and of the lab view carries: no MIME sniffing, the page's
// scripts and styles from itself only, never framed, no Referer sent on. One list for both
// servers.
#include <string>
#include <utility>
#include <vector>

namespace hystlab::web {

inline const std::vector<std::pair<std::string, std::string>>& security_headers() {
  static const std::vector<std::pair<std::string, std::string>> h{
      {"X-Content-Type-Options", "nosniff"},
      {"Content-Security-Policy", "default-src 'self'; img-src 'self' data: blob:; style-src 'self'; frame-ancestors 'none'"},
      {"X-Frame-Options", "DENY"},
      {"Referrer-Policy", "no-referrer"}};
  return h;
}

}  // namespace hystlab::web
