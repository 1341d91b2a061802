#pragma once
// The CLI's way to a running hystlabd: its HTTP API, the same door as the page's. Every verb that
// changes what a rig does (submit, pause, resume, abort, estop, a rig's reset) goes through it, so
// the daemon applies one set of checks, one token and one log to all of them. Reading records
// (list, show, export) stays on the database file: it works with no daemon running.
#include <nlohmann/json.hpp>
#include <string>

#include "cli_support.hpp"

namespace hystlab::cli {

struct DaemonAddress {
  std::string url;    // scheme://host[:port], no path: "http://127.0.0.1:8080"
  std::string token;  // empty: none sent
};

inline constexpr const char* kDefaultDaemonUrl = "http://127.0.0.1:8080";

// --daemon URL (else $HYSTLAB_DAEMON, else kDefaultDaemonUrl) and --token (else $HYSTLAB_TOKEN).
// A CliError names the option when the URL is not scheme://host[:port].
[[nodiscard]] DaemonAddress daemon_address(const Options& opt);

// POSTs body (JSON; empty: no body) to path and returns the answer's JSON. A CliError, in the
// user's words, when no daemon answers, or it refuses (the API's detail, which names the field).
nlohmann::json post_to_daemon(const DaemonAddress& to, const std::string& path, const std::string& body);

// GETs path and returns the answer's body (a report's HTML); CliErrors as post_to_daemon's.
std::string get_from_daemon(const DaemonAddress& to, const std::string& path);

// A path segment with everything but unreserved characters percent-encoded (a rig's name).
[[nodiscard]] std::string url_segment(const std::string& text);

// The CLI verbs that command the daemon take --daemon and --token, never --db: this names why.
void refuse_db_option(const std::vector<std::string>& args, const std::string& verb);

}  // namespace hystlab::cli
