#pragma once
// hystlabd: owns the rigs, the store and the writer thread; runs each rig's queued campaigns one
// after another on that rig's acquisition thread; routes operator commands; stops cleanly.
//
// Config (hystlab.json), every field optional:
//   {"db": "hystlab.db",
//    "rigs": [{"name": "frame A", "transport": "modbus-tcp", "port": 502, "time_scale": 1, ...},
//             {"name": "sim frame", "simulate": {"time_scale": 20, "noise_N": 0.05}}],
//    "http": {"bind": "127.0.0.1", "port": 8080, "token": "...", "max_stream_clients": 64}}
// With no config: one simulated load frame (hystlab-sim, supervised) and ./hystlab.db.
#include <atomic>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hystlab/control/http_config.hpp"
#include "hystlab/control/values.hpp"
#include "hystlab/daemon/envelope.hpp"
#include "hystlab/daemon/isolator.hpp"
#include "hystlab/daemon/live_feed.hpp"
#include "hystlab/daemon/plan.hpp"
#include "hystlab/daemon/realtime.hpp"
#include "hystlab/db/sample_writer.hpp"
#include "hystlab/drivers/io_health.hpp"

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
  RigEnvelope envelope;             // "envelope": what the rig can do (plans are checked against it)
  SupervisionSettings supervision;  // "supervision": dead band, lag, settle, mode, heartbeat, ...
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
};

// Throws ConfigError naming the field. A null json gives the embedded defaults.
[[nodiscard]] DaemonConfig parse_daemon_config(const nlohmann::json& j, const std::string& base_dir = ".");

// Takes the token from $HYSTLAB_TOKEN when the config has none; refuses (ConfigError) a bind
// beyond loopback without a token.
void check_http_security(HttpConfig& http, const char* env_token);

using control::campaign_command_from;
using control::CampaignCommand;
using control::CommandOutcome;
using control::RigCommand;
using control::RigInfo;
using control::RigSupervision;
using control::to_string;

// The daemon's owners: one acquisition thread per rig, the db writer thread, and the main loop
// (run) that carries out commands and keeps the snapshots. Other threads (HTTP) read the
// snapshots and live feeds, and send commands through a queue; they never touch a rig.
class Daemon {
 public:
  explicit Daemon(const DaemonConfig& config);  // opens the store, creates the rigs; throws ConfigError
  ~Daemon();
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;

  // The main loop: returns when stop becomes true, with the rigs held and the writes flushed.
  void run(const std::atomic<bool>& stop);

  [[nodiscard]] const DaemonConfig& config() const noexcept;
  [[nodiscard]] std::size_t rig_count() const noexcept;
  [[nodiscard]] const RigInfo& rig_info(std::size_t k) const;
  [[nodiscard]] const RigLive& rig_live(std::size_t k) const;
  [[nodiscard]] drivers::IoHealthSnapshot rig_health(std::size_t k) const;
  [[nodiscard]] RigSupervision rig_supervision(std::size_t k) const;
  // The rig by name (empty: the only rig); throws std::invalid_argument naming it.
  [[nodiscard]] std::size_t rig_index(const std::string& name, std::string_view plan_kind = {}) const;
  // Rig seconds per wall second of rig k (a simulator's time scale; 1 for a real rig).
  [[nodiscard]] double rig_time_scale(std::size_t k) const;
  [[nodiscard]] db::WriterStats writer_stats() const;
  [[nodiscard]] double uptime_s() const noexcept;

  // Queues a campaign on a rig (empty name: the only rig). Throws std::invalid_argument naming
  // what is wrong (the plan's field, an unknown rig, a plan the rig cannot run).
  std::int64_t submit(const std::string& rig_name, const nlohmann::json& plan);
  // What submit checks, without queuing: the plan parsed, for the rig (its index) it would run on.
  [[nodiscard]] std::pair<Plan, std::size_t> check_plan(const std::string& rig_name, const nlohmann::json& plan) const;
  // The limits a checked plan runs under on rig k: the tighter of the plan's and the rig's.
  [[nodiscard]] Limits applied_limits(const Plan& plan, std::size_t k) const;
  // A running campaign's command goes straight to its rig's thread (never through the database,
  // which may be busy); a queued or held one's through the main loop. An e-stop latches the
  // campaign's rig first (as rig_command), whatever the campaign's state.
  CommandOutcome command(std::int64_t campaign_id, CampaignCommand c);
  // The campaign's specimen and notes changed (control::DaemonInterface::set_record).
  void set_record(std::int64_t campaign_id, const nlohmann::json& changes);
  // reset or estop a rig: straight to its thread, read there every period in every state; waits
  // (at most wait_s) for the rig to confirm it, and says what happened.
  CommandOutcome rig_command(std::size_t rig, RigCommand c, double wait_s = 2.0);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Runs until stop becomes true; returns the process exit code.
int run_daemon(const DaemonConfig& config, const std::atomic<bool>& stop);

}  // namespace hystlab::daemon
