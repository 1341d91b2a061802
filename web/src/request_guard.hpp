#pragma once
// What every request passes before a route: the path, the Host (DNS rebinding), the read and
// write tokens, the origin and content type of a request that changes state, and a sane
// Content-Length. Also serves a POST that has no body at all (curl -X POST), which cpp-httplib
// 0.11 would otherwise refuse with a bare 400 before any route sees it.
#include <httplib.h>

#include "api_support.hpp"

namespace hystlab::web {

[[nodiscard]] httplib::Server::HandlerResponse guard_request(ApiContext& c, const httplib::Request& req, httplib::Response& res);

// Registers a POST route with the server, and for guard_request's bodiless dispatch.
void post_route(httplib::Server& s, ApiContext& c, const std::string& pattern, httplib::Server::Handler h);

// A read of the data (/api/..., /metrics) carries the read token (or the write token) when
// http.read_token is set; else 401. Unhandled: it may go on.
[[nodiscard]] httplib::Server::HandlerResponse check_read(const control::HttpConfig& config, const httplib::Request& req, httplib::Response& res);

// The Host header's name is one this daemon serves: an IP literal, localhost, this machine's
// name, the bound address, or one of http.allowed_hosts (a missing Host is HTTP/1.0: allowed).
[[nodiscard]] bool host_allowed(const control::HttpConfig& config, const std::string& host_header);

}  // namespace hystlab::web
