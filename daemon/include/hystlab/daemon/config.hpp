#pragma once
// hystlabd's configuration (hystlab.json): the rigs, the store, HTTP and acquisition settings,
// parsed once at start-up. Its own header: the daemon's parts (a rig worker, a supervised
// simulator) read their entry without the daemon's façade (daemon.hpp).
//
// Config, every field optional:
//   {"db": "hystlab.db",
//    "rigs": [{"name": "frame A", "transport": "modbus-tcp", "port": 502, "time_scale": 1, ...},
//             {"name": "sim frame", "simulate": {"time_scale": 20, "noise_N": 0.05}}],
//    "http": {"bind": "127.0.0.1", "port": 8080, "token": "...", "max_stream_clients": 64},
//    "lab": {"name": "materials-lab", "daemon": "frame-pc-2", "postgresql": "...", "mqtt": {...}}}
// With no config: one simulated load frame (hystlab-sim, supervised) and ./hystlab.db.
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "hystlab/control/http_config.hpp"
#include "hystlab/daemon/isolator.hpp"
#include "hystlab/daemon/realtime.hpp"
#include "hystlab/domain/envelope.hpp"
#include "hystlab/lab/lab_config.hpp"

namespace hystlab::daemon {

struct ConfigError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

struct SimulatorOptions {
  double time_scale = 10.0, noise_N = 0.05, corner_width_mm = 0.05;
  std::string rig = "load_frame";  // or "shaker"
  // An untrained specimen (load frame): the upper plateau starts extra_N higher and settles over
  // tau transformation cycles (hystlab-sim --shakedown); extra_N 0: a trained one.
  double shakedown_extra_N = 0, shakedown_tau_cycles = 0;
  // The controller's host watchdog: with the drive on, no change of host_heartbeat for this many
  // wall-clock ms stops the frame with fault 4, as a real controller does when its host is gone.
  // The daemon writes it every 0.1 s in every state; 1 s leaves room for a frozen shared machine.
  double host_timeout_ms = 1000;
  int cpu = -1;                // pinned there when >= 0 (the daemon sets its acquisition CPU)
  int realtime_priority = -1;  // > 0: SCHED_FIFO, as a controller with a CPU of its own; 0: normal;
                               // -1: one below the acquisition's when that is pinned and
                               // time_scale <= 1, else 0
};

struct RigEntry {
  std::string name;
  nlohmann::json driver;  // for make_rig (without the daemon's own fields)
  double time_scale = 1.0;
  bool simulated = false;
  SimulatorOptions sim;
  domain::RigEnvelope envelope;             // "envelope": what the rig can do (plans are checked against it)
  domain::SupervisionSettings supervision;  // "supervision": dead band, lag, settle, mode, heartbeat, ...
  // "isolator" (a shaker's; a simulated shaker's is the simulator's own): sine points are predicted with it
  std::shared_ptr<const IsolatorModel> isolator;
};

using control::HttpConfig;

struct DaemonConfig {
  std::string db_path = "hystlab.db";
  std::vector<RigEntry> rigs;
  std::string base_dir = ".";
  HttpConfig http;
  AcquisitionSettings acquisition;  // every rig's acquisition thread (and supervised simulator)
  lab::LabConfig lab;               // "lab": replication to PostgreSQL, rigs live over MQTT (docs/LAB.md)
  bool lab_view = false;            // a lab section and no rigs: the read-only view of the lab, no rig, no store
};

// Throws ConfigError naming the field. A null json gives the embedded defaults.
[[nodiscard]] DaemonConfig parse_daemon_config(const nlohmann::json& j, const std::string& base_dir = ".");

// Takes the token from $HYSTLAB_TOKEN when the config has none; refuses (ConfigError) a bind
// beyond loopback without a token.
void check_http_security(HttpConfig& http, const char* env_token);

}  // namespace hystlab::daemon
