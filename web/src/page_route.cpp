// The page's files (index.html, its scripts and styles) from the web root, as one GET route
// registered after every API route. Not cpp-httplib's mount point at "/": the library tries its
// mount points before any route, so a mount at "/" made every GET of the API build a path and
// stat a file that is not there (GET /api/status: 4.6 % of the daemon's CPU under wrk, 3.4 % of it
// the stat; stop 39's perf profile, issue 27's bench_http). Here only a request that no API route
// takes looks for a file.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "routes.hpp"

namespace hystlab::web {
namespace {

// The types a page's files have; text/javascript for its ES modules (a browser refuses a module
// of another type, and nosniff forbids it to guess).
std::string content_type(std::string_view path) {
  const auto dot = path.rfind('.');
  const std::string_view ext = dot == std::string_view::npos ? std::string_view() : path.substr(dot + 1);
  if (ext == "html") return "text/html";
  if (ext == "js" || ext == "mjs") return "text/javascript";
  if (ext == "css") return "text/css";
  if (ext == "svg") return "image/svg+xml";
  if (ext == "json" || ext == "map") return "application/json";
  if (ext == "png") return "image/png";
  if (ext == "ico") return "image/x-icon";
  if (ext == "txt") return "text/plain";
  return "application/octet-stream";
}

// A path of the page's folder: segments of letters, digits, '_', '-' and '.', none empty or
// starting with '.' (no "..", no hidden file), so no path names a place outside the root (the path
// is decoded before it is matched). A symbolic link inside the root is followed, as the mount
// point followed it: whoever installs the page's folder decides what is in it.
bool page_path(std::string_view p) {
  std::size_t from = 0;
  while (from <= p.size()) {
    const std::size_t slash = std::min(p.find('/', from), p.size());
    const std::string_view seg = p.substr(from, slash - from);
    if (seg.empty() || seg.front() == '.') return false;
    for (const char ch : seg)
      if (!(std::isalnum(static_cast<unsigned char>(ch)) != 0 || ch == '_' || ch == '-' || ch == '.')) return false;
    from = slash + 1;
  }
  return true;
}

}  // namespace

void add_page_route(httplib::Server& s, const std::string& root) {
  s.Get(R"(/(.*))", [root](const httplib::Request& req, httplib::Response& res) {
    std::string rel = req.matches[1].str();
    if (rel.empty() || rel.back() == '/') rel += "index.html";
    std::error_code ec;
    const std::filesystem::path file = std::filesystem::path(root) / rel;
    if (!page_path(rel) || !std::filesystem::is_regular_file(file, ec)) {
      res.status = 404;  // the error handler's JSON: no such resource
      return;
    }
    std::optional<std::string> body = file_bytes(file.string());
    if (!body) {
      res.status = 404;
      return;
    }
    res.set_content(std::move(*body), content_type(rel));
  });
}

}  // namespace hystlab::web
