#pragma once
// hystlabd: owns the rigs, the store and the writer thread; runs each rig's queued campaigns one
// after another on that rig's acquisition thread; routes operator commands; stops cleanly.
// Its configuration: config.hpp.
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
#include "hystlab/daemon/config.hpp"
#include "hystlab/daemon/isolator.hpp"
#include "hystlab/daemon/live_feed.hpp"
#include "hystlab/daemon/realtime.hpp"
#include "hystlab/db/sample_writer.hpp"
#include "hystlab/domain/envelope.hpp"
#include "hystlab/domain/plan.hpp"
#include "hystlab/drivers/io_health.hpp"

namespace hystlab::daemon {

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
  [[nodiscard]] std::pair<domain::Plan, std::size_t> check_plan(const std::string& rig_name, const nlohmann::json& plan) const;
  // The limits a checked plan runs under on rig k: the tighter of the plan's and the rig's.
  [[nodiscard]] domain::Limits applied_limits(const domain::Plan& plan, std::size_t k) const;
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
