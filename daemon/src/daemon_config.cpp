#include <cctype>
#include <cmath>

#include "hystlab/daemon/daemon.hpp"

namespace hystlab::daemon {
namespace {
using nlohmann::json;
[[noreturn]] void fail(const std::string& where, const std::string& why) { throw ConfigError("config: " + where + " " + why); }

double positive(const json& j, const char* f, double def, const std::string& where) {
  if (!j.contains(f)) return def;
  if (!j[f].is_number() || !(j[f].get<double>() > 0) || !std::isfinite(j[f].get<double>())) fail(where + "." + f, "must be a positive number");
  return j[f].get<double>();
}
bool loopback(const std::string& host) { return host == "127.0.0.1" || host == "localhost" || host == "::1"; }

HttpConfig parse_http(const json& h, HttpConfig c) {
  if (!h.is_object()) fail("http", "must be an object");
  for (const auto& [k, v] : h.items()) {
    if (k == "enabled") {
      if (!v.is_boolean()) fail("http.enabled", "must be true or false");
      c.enabled = v.get<bool>();
    } else if (k == "bind" || k == "token" || k == "read_token" || k == "web_root" || k == "vendor_root") {
      if (!v.is_string() || (k == "bind" && v.get<std::string>().empty())) fail("http." + k, "must be a non-empty string");
      (k == "bind" ? c.bind : k == "token" ? c.token : k == "read_token" ? c.read_token : k == "web_root" ? c.web_root : c.vendor_root) = v.get<std::string>();
    } else if (k == "allowed_hosts") {
      if (!v.is_array()) fail("http.allowed_hosts", "must be a list of host names (the names this daemon is reached by)");
      for (const auto& name : v) {
        if (!name.is_string() || name.get<std::string>().empty()) fail("http.allowed_hosts", "must be a list of non-empty host names");
        c.allowed_hosts.push_back(name.get<std::string>());
      }
    } else if (k == "port" || k == "max_stream_clients") {
      if (!v.is_number_integer() || v.get<long long>() < (k == "port" ? 0 : 1) || v.get<long long>() > (k == "port" ? 65535 : 1000))
        fail("http." + k, k == "port" ? "must be a port number (0 to 65535; 0 picks a free one)" : "must be a whole number from 1 to 1000");
      (k == "port" ? c.port : c.max_stream_clients) = v.get<int>();
    } else if (k == "max_body_bytes") {
      if (!v.is_number_integer() || v.get<long long>() < 1024) fail("http.max_body_bytes", "must be a whole number of at least 1024");
      c.max_body_bytes = v.get<std::size_t>();
    } else {
      fail("http." + k,
           "is not a known field (enabled, bind, port, token, read_token, allowed_hosts, web_root, vendor_root, max_stream_clients, "
           "max_body_bytes)");
    }
  }
  return c;
}
AcquisitionSettings parse_acquisition(const json& a) {
  if (!a.is_object()) fail("acquisition", "must be an object");
  AcquisitionSettings s;
  for (const auto& [k, v] : a.items()) {
    if (k == "priority") {
      if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() > 98)
        fail("acquisition.priority", "must be a whole number from 0 (normal scheduling) to 98 (SCHED_FIFO)");
      s.priority = v.get<int>();
    } else if (k == "cpu") {
      if (v == "last")
        s.cpu = AcquisitionSettings::kLastCpu;
      else if (v == "any")
        s.cpu = AcquisitionSettings::kAnyCpu;
      else if (v.is_number_integer() && v.get<long long>() >= 0 && v.get<long long>() < 4096)
        s.cpu = v.get<int>();
      else
        fail("acquisition.cpu", "must be a CPU number, \"last\" or \"any\"");
    } else {
      fail("acquisition." + k, "is not a known field (priority, cpu)");
    }
  }
  return s;
}

// A token guessable in a few tries is no token: at least 16 characters that are not blank.
void check_token(const std::string& token, const char* field) {
  std::size_t solid = 0;
  for (const char ch : token) solid += std::isspace(static_cast<unsigned char>(ch)) ? 0U : 1U;
  if (!token.empty() && solid < 16)
    throw ConfigError(std::string("config: ") + field + " has " + std::to_string(solid) +
                      " non-blank characters: a token needs at least 16 (e.g. from 'openssl rand -hex 16')");
}
}  // namespace

void check_http_security(HttpConfig& http, const char* env_token) {
  if (http.token.empty() && env_token && *env_token) http.token = env_token;
  check_token(http.token, "http.token (or $HYSTLAB_TOKEN)");
  check_token(http.read_token, "http.read_token");
  if (http.enabled && !loopback(http.bind) && http.token.size() < 16)
    throw ConfigError("config: http.bind is '" + http.bind +
                      "', not loopback: set a token of at least 16 characters (http.token or $HYSTLAB_TOKEN) that every "
                      "request changing state must carry");
}

DaemonConfig parse_daemon_config(const json& j, const std::string& base_dir) {
  DaemonConfig c;
  c.base_dir = base_dir;
  if (j.is_null()) {  // embedded defaults: a simulated load frame and a simulated shaker (in real time)
    c.rigs.push_back(
        RigEntry{"simulated load frame", json::object(), 1.0, true, SimulatorOptions{}, domain::RigEnvelope{}, domain::SupervisionSettings{}, nullptr});
    SimulatorOptions shaker;
    shaker.rig = "shaker";
    shaker.time_scale = 1.0;
    c.rigs.push_back(RigEntry{"simulated shaker", json::object(), 1.0, true, shaker, domain::RigEnvelope{}, domain::SupervisionSettings{},
                              std::make_shared<const IsolatorModel>(simulated_isolator())});
    return c;
  }
  if (!j.is_object()) fail("", "must be a JSON object");
  for (const auto& [k, _] : j.items())
    if (k != "db" && k != "rigs" && k != "http" && k != "acquisition" && k != "lab") fail(k, "is not a known field (db, rigs, http, acquisition, lab)");
  if (j.contains("http")) c.http = parse_http(j["http"], c.http);
  if (j.contains("lab")) {
    try {
      c.lab = lab::parse_lab_config(j["lab"], base_dir);
    } catch (const lab::LabConfigError& e) {
      throw ConfigError(e.what());
    }
  }
  if (j.contains("acquisition")) c.acquisition = parse_acquisition(j["acquisition"]);
  if (j.contains("db")) {
    if (!j["db"].is_string() || j["db"].get<std::string>().empty()) fail("db", "must be a file name");
    c.db_path = j["db"].get<std::string>();
  }
  // Only a lab section: the lab view (docs/LAB.md), no rig, no store of its own; it reads the lab's
  // PostgreSQL (and its broker, for the rigs' live state).
  if (c.lab.enabled && !j.contains("rigs")) {
    if (!c.lab.has_postgres) fail("lab.postgresql", "is missing: the lab view (a config with a lab section and no rigs) reads the lab's database");
    c.lab_view = true;
    return c;
  }
  if (!j.contains("rigs")) {
    c.rigs.push_back(
        RigEntry{"simulated load frame", json::object(), 1.0, true, SimulatorOptions{}, domain::RigEnvelope{}, domain::SupervisionSettings{}, nullptr});
    return c;
  }
  if (!j["rigs"].is_array() || j["rigs"].empty()) fail("rigs", "must be a non-empty array");
  for (std::size_t k = 0; k < j["rigs"].size(); ++k) {
    const std::string where = "rigs[" + std::to_string(k) + "]";
    json r = j["rigs"][k];
    if (!r.is_object()) fail(where, "must be an object");
    RigEntry e;
    if (r.contains("name") && (!r["name"].is_string() || r["name"].get<std::string>().empty())) fail(where + ".name", "must be a non-empty string");
    e.name = r.value("name", "rig " + std::to_string(k + 1));
    for (std::size_t m = 0; m < k; ++m)
      if (j["rigs"][m].value("name", "") == e.name) fail(where + ".name", "repeats the name of rigs[" + std::to_string(m) + "]");
    e.time_scale = positive(r, "time_scale", 1.0, where);
    r.erase("time_scale");
    if (r.contains("simulate")) {
      const json& s = r["simulate"];
      if (!s.is_object()) fail(where + ".simulate", "must be an object");
      for (const auto& [f, _] : s.items())
        if (f != "time_scale" && f != "noise_N" && f != "corner_width_mm" && f != "rig" && f != "realtime_priority" && f != "shakedown" &&
            f != "host_timeout_ms")
          fail(where + ".simulate." + f, "is not a known field");
      e.simulated = true;
      e.sim.time_scale = positive(s, "time_scale", 10.0, where + ".simulate");
      e.sim.noise_N = s.contains("noise_N") && s["noise_N"] == 0 ? 0.0 : positive(s, "noise_N", 0.05, where + ".simulate");
      e.sim.rig = s.value("rig", std::string("load_frame"));
      if (e.sim.rig != "load_frame" && e.sim.rig != "shaker") fail(where + ".simulate.rig", "must be \"load_frame\" or \"shaker\"");
      e.sim.corner_width_mm = s.contains("corner_width_mm") && s["corner_width_mm"] == 0 ? 0.0 : positive(s, "corner_width_mm", 0.05, where + ".simulate");
      if (s.contains("shakedown")) {  // [extra_N, tau_cycles]
        const json& sd = s["shakedown"];
        if (!sd.is_array() || sd.size() != 2 || !sd[0].is_number() || !sd[1].is_number() || !(sd[0].get<double>() > 0) || !(sd[1].get<double>() > 0) ||
            sd[0].get<double>() > 1e4 || sd[1].get<double>() > 1e4)
          fail(where + ".simulate.shakedown", "must be [extra_N, tau_cycles], both above 0 (e.g. [8, 4])");
        if (e.sim.rig != "load_frame") fail(where + ".simulate.shakedown", "applies to a load frame's specimen only");
        e.sim.shakedown_extra_N = sd[0].get<double>();
        e.sim.shakedown_tau_cycles = sd[1].get<double>();
      }
      if (s.contains("realtime_priority")) {
        const json& p = s["realtime_priority"];
        if (!p.is_number_integer() || p.get<long long>() < 0 || p.get<long long>() > 98)
          fail(where + ".simulate.realtime_priority", "must be an integer from 0 (normal scheduling) to 98");
        e.sim.realtime_priority = p.get<int>();
      }
      if (s.contains("host_timeout_ms")) {
        const json& h = s["host_timeout_ms"];
        if (!h.is_number() || !(h.get<double>() >= 0) || h.get<double>() > 60000)
          fail(where + ".simulate.host_timeout_ms", "must be a number of milliseconds from 0 (no host watchdog) to 60000");
        e.sim.host_timeout_ms = h.get<double>();
      }
      r.erase("simulate");
    }  // driver fields are checked by make_rig when the daemon creates the rigs, before anything runs
    const bool shaker = e.simulated ? e.sim.rig == "shaker" : r.value("rig", std::string("load_frame")) == "shaker";
    try {
      e.envelope = domain::parse_envelope(r.value("envelope", json()), where + ".envelope", shaker);
      e.supervision = domain::parse_supervision(r.value("supervision", json()), where + ".supervision");
    } catch (const domain::RigConfigError& err) {
      throw ConfigError(err.what());
    }
    r.erase("envelope");
    r.erase("supervision");
    try {
      if (r.contains("isolator")) {
        if (!shaker) throw std::invalid_argument("config: " + where + ".isolator is for a shaker's isolator; this rig is a load frame");
        e.isolator = std::make_shared<const IsolatorModel>(parse_isolator(r["isolator"], where + ".isolator"));
      } else if (e.simulated && shaker) {
        e.isolator = std::make_shared<const IsolatorModel>(simulated_isolator());
      }
    } catch (const IsolatorError& err) {
      throw ConfigError(std::string("config: ") + err.what());
    } catch (const std::invalid_argument& err) {
      throw ConfigError(err.what());
    }
    r.erase("isolator");
    e.driver = r;
    c.rigs.push_back(e);
  }
  return c;
}

}  // namespace hystlab::daemon
