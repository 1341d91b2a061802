#include "daemon_client.hpp"

#include <httplib.h>

#include <cctype>
#include <cstdlib>
#include <regex>

namespace hystlab::cli {
namespace {

std::string env_or(const char* name, const std::string& fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::string(v) : fallback;
}

// What the API said, in one line: its detail (which names the field), else its kind of error.
std::string api_reason(const httplib::Response& r) {
  const auto j = nlohmann::json::parse(r.body, nullptr, false);
  if (j.is_object()) {
    if (j.contains("detail") && j["detail"].is_string() && !j["detail"].get<std::string>().empty()) return j["detail"];
    if (j.contains("error") && j["error"].is_string()) return j["error"];
  }
  std::string excerpt = r.body.substr(0, 200);
  for (char& ch : excerpt)
    if (ch == '\n' || ch == '\r') ch = ' ';  // the CLI's errors are one line
  return "HTTP " + std::to_string(r.status) + (excerpt.empty() ? "" : ": " + excerpt);
}

// One place for the two waits: the calls below and the messages that name them.
constexpr int kConnectSeconds = 5;
constexpr int kAnswerSeconds = 30;  // a submit waits for the daemon's main loop; a busy database can take seconds

// httplib's names for a failed request ("Connection", "Read"), in the words of a lab user.
std::string failure_words(httplib::Error e) {
  switch (e) {
    case httplib::Error::Connection:
      return "nothing accepts a connection there";
    case httplib::Error::ConnectionTimeout:
      return "no connection within " + std::to_string(kConnectSeconds) + " s";
    case httplib::Error::SSLConnection:
    case httplib::Error::SSLServerVerification:
      return "no TLS connection (" + httplib::to_string(e) + ")";
    default:
      return httplib::to_string(e);
  }
}

}  // namespace

DaemonAddress daemon_address(const Options& opt) {
  DaemonAddress a;
  const bool given = opt.has("daemon");
  a.url = given ? opt.get("daemon") : env_or("HYSTLAB_DAEMON", kDefaultDaemonUrl);
  const char* source = given ? "--daemon" : "$HYSTLAB_DAEMON";
  static const std::regex url(R"(^https?://([A-Za-z0-9.\-]+|\[[0-9:]+\])(:[0-9]{1,5})?/?$)");  // cpp-httplib 0.11: IPv6 of digits only
  if (!std::regex_match(a.url, url))
    throw CliError(std::string(source) + ": '" + a.url + "' is not the daemon's address like " + kDefaultDaemonUrl + " (scheme, host, port; no path)");
  if (a.url.back() == '/') a.url.pop_back();
  a.token = opt.has("token") ? opt.get("token") : env_or("HYSTLAB_TOKEN", "");
  return a;
}

namespace {
httplib::Headers token_headers(const DaemonAddress& to) {
  httplib::Headers headers;
  if (!to.token.empty()) headers.emplace("Authorization", "Bearer " + to.token);
  return headers;
}
void set_waits(httplib::Client& client) {
  client.set_connection_timeout(kConnectSeconds, 0);
  client.set_read_timeout(kAnswerSeconds, 0);
}
// No answer, a token asked for, a refusal: each a CliError in the user's words.
void check_answer(const DaemonAddress& to, const httplib::Result& r) {
  if (!r)
    throw CliError("no hystlabd answers at " + to.url + " (" + failure_words(r.error()) +
                   "): start it, or give its address with --daemon URL or $HYSTLAB_DAEMON");
  if (r->status == 401) throw CliError("hystlabd at " + to.url + " needs its token (" + api_reason(*r) + "): give it with --token or $HYSTLAB_TOKEN");
  if (r->status < 200 || r->status >= 300) throw CliError(api_reason(*r));
}
}  // namespace

nlohmann::json post_to_daemon(const DaemonAddress& to, const std::string& path, const std::string& body) {
  httplib::Client client(to.url);
  set_waits(client);
  const httplib::Headers headers = token_headers(to);
  const auto r = body.empty() ? client.Post(path.c_str(), headers) : client.Post(path.c_str(), headers, body, "application/json");
  if (!r && r.error() == httplib::Error::Read)  // it may have acted: a blind retry could queue a campaign twice
    throw CliError("hystlabd at " + to.url + " did not answer within " + std::to_string(kAnswerSeconds) +
                   " s; it may still carry the request out: check with 'hystlab campaign list' before sending it again");
  if (!r && r.error() == httplib::Error::Write)
    throw CliError("hystlabd at " + to.url + " closed the connection while the request was sent (a plan larger than its http.max_body_bytes?)");
  check_answer(to, r);
  const auto j = nlohmann::json::parse(r->body, nullptr, false);
  if (j.is_discarded()) throw CliError("hystlabd at " + to.url + " answered " + std::to_string(r->status) + " with no JSON: is it hystlabd?");
  return j;
}

std::string get_from_daemon(const DaemonAddress& to, const std::string& path) {
  httplib::Client client(to.url);
  set_waits(client);
  const auto r = client.Get(path.c_str(), token_headers(to));
  check_answer(to, r);
  return r->body;
}

std::string url_segment(const std::string& text) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (std::isalnum(c) || ch == '-' || ch == '_' || ch == '.' || ch == '~') {
      out += ch;
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

void refuse_db_option(const std::vector<std::string>& args, const std::string& verb) {
  for (const auto& a : args)
    if (a == "--db" || a.rfind("--db=", 0) == 0)
      throw CliError("--db: '" + verb + "' is sent to the running hystlabd, which owns the database: give its address with --daemon URL (default " +
                     kDefaultDaemonUrl + ")");
}

}  // namespace hystlab::cli
