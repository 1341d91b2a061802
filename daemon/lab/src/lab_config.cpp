#include "hystlab/lab/lab_config.hpp"

#include "hystlab/db/pg.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace hystlab::lab {
namespace {
using nlohmann::json;

[[noreturn]] void fail(const std::string& where, const std::string& why) { throw LabConfigError("config: lab." + where + " " + why); }

std::string text(const json& v, const std::string& where) {
  if (!v.is_string() || v.get<std::string>().empty()) fail(where, "must be a non-empty string");
  return v.get<std::string>();
}

const char* real_env(const char* name) { return std::getenv(name); }

// A password named by a file (its first line) or an environment variable: never the JSON itself.
std::string secret(const json& section, const std::string& prefix, const std::string& where, const std::string& base_dir, const char* (*env)(const char*)) {
  const std::string file_key = prefix + "_file", env_key = prefix + "_env";
  if (section.contains(file_key) && section.contains(env_key)) fail(where + file_key, "and " + env_key + " name two passwords: give one");
  if (section.contains(file_key)) {
    std::filesystem::path p = text(section[file_key], where + file_key);
    if (p.is_relative()) p = std::filesystem::path(base_dir) / p;
    std::ifstream in(p);
    if (!in) fail(where + file_key, "names '" + p.string() + "', which cannot be read");
    std::string line;
    std::getline(in, line);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (line.empty()) fail(where + file_key, "names '" + p.string() + "', whose first line is empty");
    return line;
  }
  if (section.contains(env_key)) {
    const std::string name = text(section[env_key], where + env_key);
    const char* v = env(name.c_str());
    if (v == nullptr || *v == '\0') fail(where + env_key, "names $" + name + ", which is not set");
    return v;
  }
  return {};
}

// libpq takes a URL (postgresql://user:password@host/db) or key=value pairs (password=...): a
// password in either would put it in the config's JSON, which is refused (db::conninfo_has_password,
// which `hystlab lab --pg` asks too).
void refuse_inline_password(const std::string& conninfo) {
  if (db::conninfo_has_password(conninfo))
    fail("postgresql", "holds a password: give it in lab.postgresql_password_file or lab.postgresql_password_env, never in the config");
}

MqttSettings parse_mqtt(const json& m, const std::string& base_dir, const char* (*env)(const char*)) {
  if (!m.is_object()) fail("mqtt", "must be an object (host, port, client_id, username, password_file, ...)");
  MqttSettings s;
  for (const auto& [k, v] : m.items()) {
    const std::string where = "mqtt." + k;
    if (k == "host" || k == "client_id" || k == "username" || k == "ca_file" || k == "cert_file" || k == "key_file") {
      std::string t = text(v, where);
      if ((k == "ca_file" || k == "cert_file" || k == "key_file") && std::filesystem::path(t).is_relative()) t = (std::filesystem::path(base_dir) / t).string();
      (k == "host"        ? s.host
       : k == "client_id" ? s.client_id
       : k == "username"  ? s.username
       : k == "ca_file"   ? s.ca_file
       : k == "cert_file" ? s.cert_file
                          : s.key_file) = t;
    } else if (k == "port") {
      if (!v.is_number_integer() || v.get<long long>() < 1 || v.get<long long>() > 65535) fail(where, "must be a port number (1 to 65535)");
      s.port = v.get<int>();
    } else if (k == "keepalive_s") {
      if (!v.is_number_integer() || v.get<long long>() < 5 || v.get<long long>() > 3600) fail(where, "must be a whole number of seconds from 5 to 3600");
      s.keepalive_s = v.get<int>();
    } else if (k == "live_rate_hz") {
      if (!v.is_number() || !(v.get<double>() >= 0.1 && v.get<double>() <= 100)) fail(where, "must be a number of batches a second from 0.1 to 100");
      s.live_rate_hz = v.get<double>();
    } else if (k == "queue_limit") {
      if (!v.is_number_integer() || v.get<long long>() < 10 || v.get<long long>() > 1000000) fail(where, "must be a whole number from 10 to 1000000");
      s.queue_limit = v.get<std::size_t>();
    } else if (k == "password") {
      fail(where, "is refused: a password never sits in the config; name it with mqtt.password_file or mqtt.password_env");
    } else if (k != "password_file" && k != "password_env") {
      fail(where,
           "is not a known field (host, port, client_id, username, password_file, password_env, ca_file, cert_file, key_file, "
           "keepalive_s, live_rate_hz, queue_limit)");
    }
  }
  s.password = secret(m, "password", "mqtt.", base_dir, env);
  if (!s.password.empty() && s.username.empty()) fail("mqtt.username", "is missing: a password was given without a user name");
  if (s.cert_file.empty() != s.key_file.empty()) fail(s.cert_file.empty() ? "mqtt.cert_file" : "mqtt.key_file", "is missing: a client certificate needs both");
  // TLS is on when ca_file is set; a client certificate without it would be silently unused.
  if (!s.cert_file.empty() && s.ca_file.empty())
    fail("mqtt.cert_file", "is given without lab.mqtt.ca_file: TLS needs the CA that signed the broker's certificate");
  // Read now, not at the first connection: a wrong path is a config error at start, not a
  // publisher that retries for ever.
  for (const auto& [field, file] : {std::pair{"ca_file", &s.ca_file}, {"cert_file", &s.cert_file}, {"key_file", &s.key_file}})
    if (!file->empty() && !std::ifstream(*file)) fail(std::string("mqtt.") + field, "names '" + *file + "', which cannot be read");
  return s;
}
}  // namespace

bool valid_name(const std::string& s) noexcept {
  if (s.empty() || s.size() > 64) return false;
  for (const char c : s)
    if (c == '/' || c == '+' || c == '#' || c == '\0' || static_cast<unsigned char>(c) < 0x20) return false;
  return true;
}

LabConfig parse_lab_config(const json& j, const std::string& base_dir, const char* (*env)(const char*)) {
  if (env == nullptr) env = real_env;
  if (!j.is_object()) throw LabConfigError("config: lab must be an object (name, daemon, postgresql, mqtt)");
  LabConfig c;
  c.enabled = true;
  for (const auto& [k, v] : j.items()) {
    if (k == "name" || k == "daemon") {
      const std::string t = text(v, k);
      if (!valid_name(t)) fail(k, "'" + t + "' cannot be a topic level: up to 64 characters, none of '/', '+', '#'");
      (k == "name" ? c.name : c.daemon) = t;
    } else if (k == "url") {
      c.url = text(v, k);
      if (c.url.rfind("http://", 0) != 0 && c.url.rfind("https://", 0) != 0) fail(k, "must be this daemon's page as an http:// or https:// address");
    } else if (k == "postgresql") {
      c.postgres.conninfo = text(v, k);
      refuse_inline_password(c.postgres.conninfo);
      c.has_postgres = true;
    } else if (k == "replicate_every_s") {
      if (!v.is_number() || !(v.get<double>() >= 0.05 && v.get<double>() <= 3600)) fail(k, "must be a number of seconds from 0.05 to 3600");
      c.postgres.period_s = v.get<double>();
    } else if (k == "mqtt") {
      c.mqtt = parse_mqtt(v, base_dir, env);
      c.has_mqtt = true;
    } else if (k == "postgresql_password_file" || k == "postgresql_password_env") {
      if (!j.contains("postgresql")) fail(k, "is given without lab.postgresql");
    } else {
      fail(k, "is not a known field (name, daemon, url, postgresql, postgresql_password_file, postgresql_password_env, replicate_every_s, mqtt)");
    }
  }
  if (c.name.empty()) fail("name", "is missing: the lab's name (e.g. \"materials-lab\") keys its topics and rows");
  if (c.daemon.empty()) fail("daemon", "is missing: this daemon's name in the lab (e.g. its host, \"frame-pc-2\")");
  if (c.has_postgres) c.postgres.password = secret(j, "postgresql_password", "", base_dir, env);
  if (c.has_mqtt && c.mqtt.client_id.empty()) c.mqtt.client_id = "hystlabd-" + c.name + "-" + c.daemon;
  return c;
}

}  // namespace hystlab::lab
