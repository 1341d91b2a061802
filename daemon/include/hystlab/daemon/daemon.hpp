#pragma once
// hystlabd: owns the rigs, the store and the writer thread; runs each rig's queued campaigns one
// after another on that rig's acquisition thread; routes operator commands; stops cleanly.
//
// Config (hystlab.json), every field optional:
//   {"db": "hystlab.db",
//    "rigs": [{"name": "frame A", "transport": "modbus-tcp", "port": 502, "time_scale": 1, ...},
//             {"name": "sim frame", "simulate": {"time_scale": 20, "noise_N": 0.05}}]}
// With no config: one simulated load frame (hystlab-sim, supervised) and ./hystlab.db.
#include <atomic>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace hystlab::daemon {

struct ConfigError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

struct SimulatorOptions {
  double time_scale = 10.0, noise_N = 0.05, corner_width_mm = 0.05;
  std::string rig = "load_frame";  // or "shaker"
};

struct RigEntry {
  std::string name;
  nlohmann::json driver;  // for make_rig (without the daemon's own fields)
  double time_scale = 1.0;
  bool simulated = false;
  SimulatorOptions sim;
};

struct DaemonConfig {
  std::string db_path = "hystlab.db";
  std::vector<RigEntry> rigs;
  std::string base_dir = ".";
};

// Throws ConfigError naming the field. A null json gives the embedded defaults.
[[nodiscard]] DaemonConfig parse_daemon_config(const nlohmann::json& j, const std::string& base_dir = ".");

// Runs until stop becomes true; returns the process exit code.
int run_daemon(const DaemonConfig& config, const std::atomic<bool>& stop);

}  // namespace hystlab::daemon
