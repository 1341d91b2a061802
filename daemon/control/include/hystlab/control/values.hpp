#pragma once
// The values the daemon's interface hands out: copies, owned by the caller, safe to keep. Text
// appears only where it is shown as is (names, reasons); states and commands are enums.
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hystlab/domain/campaign.hpp"
#include "hystlab/domain/plan_error.hpp"
#include "hystlab/domain/signals.hpp"

namespace hystlab::control {

// A plan the daemon refuses (the domain's: what() in the form's words, field the plan's field).
using domain::PlanError;

struct RigInfo {
  std::int64_t id = 0;
  std::string name, description;
  domain::RigKind kind = domain::RigKind::load_frame;
  bool simulated = false;
};

// Operator commands for a rig itself, whatever campaign runs (or none). recover: a load frame
// latched beyond its stroke is brought back into it at the safe rate (limit recovery).
enum class RigCommand { reset, estop, recover };

// What became of an operator's command, as its answer says it (rig and campaign commands).
struct CommandOutcome {
  enum class Result {
    done,         // carried out (an e-stop: latched; a reset: the rig reports ready again)
    pending,      // taken, not yet confirmed within the answer's wait (reason says what is awaited)
    conflict,     // does not apply in this state (reason says why): nothing was done
    unreachable,  // the rig did not take the write (an e-stop stays latched here and is re-sent)
    refused,      // the rig refused it (a reset while the cause is present)
  };
  Result result = Result::done;
  bool latched = false;    // the rig's supervision is latched (e-stop or fault) after the command
  bool confirmed = false;  // the rig's status word shows it (the e-stop bit; ready and clear)
  std::string state;       // the rig's supervision state (rig commands) or the campaign's
  std::string reason;
  double waited_s = 0;  // from the request to the answer
};
[[nodiscard]] const char* to_string(CommandOutcome::Result r) noexcept;

// Operator commands for a campaign: the domain's (one enum from the API to the rig's thread).
using domain::campaign_command_from;
using domain::CampaignCommand;
using domain::commands_for;

// The rig's supervision (a copy, taken under a lock).
struct RigSupervision {
  std::string state = "disconnected";  // the supervisor's RigState, as text at this edge
  bool latched = false, resetting = false, recovering = false, have_sample = false;
  std::string latch_reason, reset_refusal;
  std::string recovery_result;                    // the last limit recovery's outcome, in words
  std::uint16_t latched_fault_code = 0;           // the code that latched (0: an e-stop or none)
  std::uint16_t status_word = 0, fault_code = 0;  // the last sample's
  std::string fault_text;                         // the map's text for fault_code
  double position_mm = 0, force_N = 0;
  std::uint64_t link_losses = 0, transitions = 0;
  std::vector<nlohmann::json> recent;  // the last transitions: at, t, from, to, reason
  nlohmann::json envelope, supervision;
};

// One live sample of a rig, as its acquisition thread saw it.
// A rig's live sample: three values, those of its kind's live signals (domain::live_signals):
// a load frame's command, displacement and force, a shaker's base and mass motion.
struct LiveSample {
  double mono_s = 0;          // host steady clock when acquired (the same clock in every process here)
  double t = 0;               // rig time
  std::array<double, 3> v{};  // in the order of domain::live_signals(kind): frame() or shaker()
  std::int64_t run = 0;       // 0: the rig is idle (a sample read between campaigns)
  std::uint32_t status = 0;

  [[nodiscard]] static LiveSample of(double mono, double t, const domain::FrameSample& s, std::int64_t run, std::uint32_t status) noexcept {
    return {mono, t, {s.command_mm, s.displacement_mm, s.force_N}, run, status};
  }
  [[nodiscard]] static LiveSample of(double mono, double t, const domain::LiveShaker& s, std::int64_t run, std::uint32_t status) noexcept {
    return {mono, t, {s.base_displacement_mm, s.mass_displacement_mm, s.mass_accel_m_s2}, run, status};
  }
  [[nodiscard]] domain::FrameSample frame() const noexcept { return {v[0], v[1], v[2]}; }
  [[nodiscard]] domain::LiveShaker shaker() const noexcept { return {v[0], v[1], v[2]}; }
};

// The rig link's I/O health.
struct LinkHealth {
  std::uint64_t reads = 0, writes = 0, reconnects = 0;
  std::uint64_t lost_samples = 0;                             // gaps in a controller's sample counter that no block read filled
  std::vector<std::pair<std::string, std::uint64_t>> errors;  // by kind: "timeout", "crc_error", ...
  double last_transaction_us = 0, max_transaction_us = 0, total_transaction_us = 0;
  std::vector<std::uint64_t> latency_histogram_us;  // bucket k: [2^k, 2^(k+1)) µs; the last is open
};

// The rig's acquisition counters.
struct AcquisitionCounters {
  std::uint64_t samples = 0, missed_deadlines = 0, late_wakeups = 0;
  std::int64_t campaign = 0, run = 0;  // 0: none running
  double sample_rate_hz = 0;           // the running campaign's
  std::string phase = "none";          // what its loop is doing: arming, ramping, dwelling, paused, safing, ...
  double submit_latency_s = -1;        // the newest submission's, call to the rig's thread taking it (-1: none)
};

struct WriterCounters {
  std::uint64_t written = 0, depth = 0, dropped = 0, commits = 0;
};

// What a daemon shares with its lab (docs/LAB.md), as /api/status, /metrics and the page show it.
struct ReplicationCounters {
  bool configured = false, connected = false;
  std::string error;                   // the last failure's reason; empty once a pass succeeds
  std::int64_t backlog_samples = 0;    // samples in SQLite not yet in PostgreSQL
  std::int64_t samples = 0, rows = 0;  // copied since the daemon started (rows: every table's)
  double lag_s = 0;                    // everything SQLite held this long ago is in PostgreSQL
  std::uint64_t passes = 0, failures = 0;
};
struct MqttCounters {
  bool configured = false, connected = false;
  std::string error;
  std::uint64_t published = 0, dropped = 0, reconnects = 0;
};
struct LabCounters {
  std::string lab, daemon;  // empty: no "lab" section
  ReplicationCounters replication;
  MqttCounters mqtt;
};

// What a plan will do, before it is submitted.
struct PlanPreview {
  domain::CampaignKind kind = domain::CampaignKind::fot;
  double duration_s = 0;                         // rig seconds, from the rig at the range's bottom
  std::size_t nodes = 0;                         // FOT nodes measured (fot), frequencies (sine)
  double peak_speed_mm_s = 0;                    // commanded
  double peak_force_N = 0;                       // predicted by the model on the plan's input (load frames)
  double peak_accel_m_s2 = 0;                    // of the base (shakers)
  double samples = 0;                            // duration × sample rate
  double sample_rate_hz = 0, force_limit_N = 0;  // the plan's
  // An adaptive FOT design's budget for its rows (0: none): duration_s counts the coarse rows'
  // ramps as the whole budget spent, the most the design may take.
  double design_budget_s = 0;
  // Rig seconds per wall second (a simulator faster than real time): the campaign then takes
  // duration_s / time_scale of wall time, and the host, sampling at sample_rate_hz of wall time,
  // stores sample_rate_hz / time_scale of rig time.
  double time_scale = 1;
  // The plan's limits that the rig's envelope tightens, in sentences (what applies instead).
  std::vector<std::string> limits_applied;
};

}  // namespace hystlab::control
