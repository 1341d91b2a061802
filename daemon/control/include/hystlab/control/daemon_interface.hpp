#pragma once
// The daemon as a front end sees it (web/, and any other): submit a plan, send a command, read
// snapshots. Every answer is a value the caller owns; nothing here exposes a rig, a thread, a
// driver or the database's writer. Calls are safe from any thread. hystlab::daemon implements
// it (hystlab/daemon/daemon_control.hpp); a test can implement it with a fake.
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "hystlab/control/values.hpp"
#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::control {

class DaemonInterface {
 public:
  virtual ~DaemonInterface() = default;

  // Rigs, by index 0..rig_count()-1 (fixed while the daemon runs).
  [[nodiscard]] virtual std::size_t rig_count() const noexcept = 0;
  [[nodiscard]] virtual RigInfo rig_info(std::size_t rig) const = 0;
  [[nodiscard]] virtual RigSupervision rig_supervision(std::size_t rig) const = 0;
  [[nodiscard]] virtual LinkHealth rig_health(std::size_t rig) const = 0;
  [[nodiscard]] virtual AcquisitionCounters rig_counters(std::size_t rig) const = 0;
  // The rig by name; empty: the only rig, or the only one that can run a plan of plan_kind (a
  // sine plan: a shaker; any other: a load frame). Throws std::invalid_argument naming the rigs.
  [[nodiscard]] virtual std::size_t rig_index(const std::string& name, std::string_view plan_kind = {}) const = 0;
  // reset or estop a rig: straight to its thread, which reads its commands every period in every
  // state (idle, arming, running, paused, safing, a campaign being finished). Returns once carried
  // out (an e-stop latched and seen in the rig's status word; a reset confirmed by the rig) or
  // refused, or after a bounded wait with what is known then (pending).
  virtual CommandOutcome rig_command(std::size_t rig, RigCommand c) = 0;

  // Live samples: indices count every sample the rig's thread published. live_head is one past
  // the newest; read_live appends samples [from, head) taking every stride-th, skips (and counts
  // in *lost) those already overwritten, and returns where to read next.
  [[nodiscard]] virtual std::uint64_t live_head(std::size_t rig) const noexcept = 0;
  virtual std::uint64_t read_live(std::size_t rig, std::uint64_t from, std::size_t stride, std::vector<LiveSample>& out,
                                  std::uint64_t* lost = nullptr) const = 0;

  // Queues a campaign. Throws PlanError (naming the plan's field) or std::invalid_argument (an
  // unknown rig, a plan the rig cannot run, a latched rig).
  virtual std::int64_t submit(const std::string& rig, const nlohmann::json& plan) = 0;
  // What submit checks, and what the plan would do; model: the force model for the peak force
  // (load frames), or null.
  [[nodiscard]] virtual PlanPreview preview(const std::string& rig, const nlohmann::json& plan, models::HysteresisModel* model) const = 0;
  // A campaign's command. conflict when it does not apply to the campaign's state (the reason
  // says why); an e-stop latches the campaign's rig as rig_command does, then ends the campaign.
  virtual CommandOutcome command(std::int64_t campaign, CampaignCommand c) = 0;
  // Changes what the lab records with a campaign, in any state: changes holds "specimen" and/or
  // "notes" (text); the others stay. Kept as a "record" event (every change, with its time).
  // Throws PlanError naming the field, std::out_of_range for an unknown campaign.
  virtual void set_record(std::int64_t campaign, const nlohmann::json& changes) = 0;

  [[nodiscard]] virtual WriterCounters writer() const = 0;
  [[nodiscard]] virtual double uptime_s() const noexcept = 0;
  [[nodiscard]] virtual std::string db_path() const = 0;
  // A thread with long-lived, low-priority work (an event stream) keeps off the acquisition's
  // CPU while off is true; false gives it back every CPU. Best effort.
  virtual void keep_off_acquisition_cpu(bool off) const noexcept = 0;
};

}  // namespace hystlab::control
