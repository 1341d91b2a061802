#include <cmath>

#include "hystlab/daemon/daemon.hpp"

namespace hystlab::daemon {
namespace {
using nlohmann::json;
[[noreturn]] void fail(const std::string& where, const std::string& why) { throw ConfigError("config: " + where + " " + why); }

double positive(const json& j, const char* f, double def, const std::string& where) {
  if (!j.contains(f)) return def;
  if (!j[f].is_number() || !(j[f].get<double>() > 0) || !std::isfinite(j[f].get<double>()))
    fail(where + "." + f, "must be a positive number");
  return j[f].get<double>();
}
}  // namespace

DaemonConfig parse_daemon_config(const json& j, const std::string& base_dir) {
  DaemonConfig c;
  c.base_dir = base_dir;
  if (j.is_null()) {  // embedded defaults: one simulated load frame
    c.rigs.push_back(RigEntry{"simulated load frame", json::object(), 1.0, true, SimulatorOptions{}});
    return c;
  }
  if (!j.is_object()) fail("", "must be a JSON object");
  for (const auto& [k, _] : j.items())
    if (k != "db" && k != "rigs") fail(k, "is not a known field (db, rigs)");
  if (j.contains("db")) {
    if (!j["db"].is_string() || j["db"].get<std::string>().empty()) fail("db", "must be a file name");
    c.db_path = j["db"].get<std::string>();
  }
  if (!j.contains("rigs")) {
    c.rigs.push_back(RigEntry{"simulated load frame", json::object(), 1.0, true, SimulatorOptions{}});
    return c;
  }
  if (!j["rigs"].is_array() || j["rigs"].empty()) fail("rigs", "must be a non-empty array");
  for (std::size_t k = 0; k < j["rigs"].size(); ++k) {
    const std::string where = "rigs[" + std::to_string(k) + "]";
    json r = j["rigs"][k];
    if (!r.is_object()) fail(where, "must be an object");
    RigEntry e;
    if (r.contains("name") && (!r["name"].is_string() || r["name"].get<std::string>().empty()))
      fail(where + ".name", "must be a non-empty string");
    e.name = r.value("name", "rig " + std::to_string(k + 1));
    for (std::size_t m = 0; m < k; ++m)
      if (j["rigs"][m].value("name", "") == e.name) fail(where + ".name", "repeats the name of rigs[" + std::to_string(m) + "]");
    e.time_scale = positive(r, "time_scale", 1.0, where);
    r.erase("time_scale");
    if (r.contains("simulate")) {
      const json& s = r["simulate"];
      if (!s.is_object()) fail(where + ".simulate", "must be an object");
      for (const auto& [f, _] : s.items())
        if (f != "time_scale" && f != "noise_N" && f != "corner_width_mm" && f != "rig") fail(where + ".simulate." + f, "is not a known field");
      e.simulated = true;
      e.sim.time_scale = positive(s, "time_scale", 10.0, where + ".simulate");
      e.sim.noise_N = s.contains("noise_N") && s["noise_N"] == 0 ? 0.0 : positive(s, "noise_N", 0.05, where + ".simulate");
      e.sim.rig = s.value("rig", std::string("load_frame"));
      if (e.sim.rig != "load_frame" && e.sim.rig != "shaker") fail(where + ".simulate.rig", "must be \"load_frame\" or \"shaker\"");
      e.sim.corner_width_mm = s.contains("corner_width_mm") && s["corner_width_mm"] == 0 ? 0.0 : positive(s, "corner_width_mm", 0.05, where + ".simulate");
      r.erase("simulate");
    }  // driver fields are checked by make_rig when the daemon creates the rigs, before anything runs
    e.driver = r;
    c.rigs.push_back(e);
  }
  return c;
}

}  // namespace hystlab::daemon
