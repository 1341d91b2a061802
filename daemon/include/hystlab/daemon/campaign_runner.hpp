#pragma once
// One campaign on one rig, on the acquisition thread: arm, drive the plan's input, sample at the
// plan's rate on absolute deadlines, enforce the safety envelope and the watchdog, fit the
// Preisach table online, and finish (or abort to the safe position) with every transition stored.
// The disk is written only by the writer thread (samples through its ring, the rest as jobs).
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "hystlab/daemon/live_feed.hpp"
#include "hystlab/daemon/plan.hpp"
#include "hystlab/db/sample_writer.hpp"
#include "hystlab/drivers/rig.hpp"
#include "hystlab/models/fot_node.hpp"
#include <vector>

namespace hystlab::daemon {

enum class Control { pause, resume, abort, estop };  // estop: the rig's e-stop, now; no motion

struct RunnerContext {
  RunnerContext(drivers::Rig& r, db::SampleWriter& w, db::Store& s) : rig(r), writer(w), store(s) {}
  drivers::Rig& rig;
  db::SampleWriter& writer;
  db::Store& store;                                     // this thread's connection, used outside the loop
  double time_scale = 1.0;                              // rig seconds per wall second (a time-scaled simulator)
  std::function<std::optional<Control>()> next_control = [] { return std::nullopt; };
  const std::atomic<bool>* stop = nullptr;              // the daemon is shutting down: hold, interrupted
  double resume_preamble_after_s = 2.0;                 // rig seconds of pause after which memory is re-wiped
  int watchdog_hold_periods = 20, watchdog_fail_periods = 500;
  std::function<std::string()> now_iso;                 // wall-clock stamps for the records
  std::function<void(const std::string&)> on_state;     // observers (logs, tests)
  // Resuming an interrupted campaign: the nodes its earlier runs measured. Rows they complete
  // are not driven again; the rest follow a wipe-out preamble to δmin.
  std::vector<models::FotNode> prior_nodes;
  RigLive* live = nullptr;                        // when set, every sample and missed deadline is shown there
  std::vector<float>* loop_periods_us = nullptr;  // when set, every tick's period is recorded (benchmarks)
};

struct RunnerResult {
  std::string state, reason;
  std::int64_t run_id = 0;
  // missed_deadlines: samples not taken in time. Polling the latest value, that is a loop period
  // started a whole period late (a late wake-up); with block reads, a sample lost because the
  // controller's buffer overran before it was read. Late wake-ups are counted in both modes.
  std::uint64_t samples = 0, missed_deadlines = 0, late_wakeups = 0, dropped = 0;
  std::size_t nodes = 0;
  std::optional<std::int64_t> table_id, lsq_table_id;
};

// Runs the campaign (already stored as 'queued') to its end state; never throws for rig errors.
// fot and waveform plans drive a load frame; sine plans a shaker (run_sine_campaign).
RunnerResult run_campaign(std::int64_t campaign_id, const Plan& plan, RunnerContext& ctx);
RunnerResult run_sine_campaign(std::int64_t campaign_id, const Plan& plan, RunnerContext& ctx);

}  // namespace hystlab::daemon
