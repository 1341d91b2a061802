#pragma once
// One campaign on one rig, on the rig's acquisition thread: one loop for every campaign kind
// (deadlines, controls, supervision, safety, watchdog, gap accounting, publishing to the writer
// and the live ring), with the kinds (fot, waveform, sine) as strategies that produce setpoints
// and consume samples. The loop never touches the database: samples go through the writer's
// ring, everything else as writer jobs; the final fits run off this thread (RunnerContext::finish).
#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hystlab/daemon/clock.hpp"
#include "hystlab/daemon/isolator.hpp"
#include "hystlab/daemon/live_feed.hpp"
#include "hystlab/daemon/run_series.hpp"
#include "hystlab/daemon/supervisor.hpp"
#include "hystlab/db/sample_writer.hpp"
#include "hystlab/domain/campaign.hpp"
#include "hystlab/domain/plan.hpp"
#include "hystlab/drivers/rig.hpp"
#include "hystlab/models/fot_node.hpp"
#include "hystlab/models/online_table_builder.hpp"

namespace hystlab::daemon {

// An operator's command as the rig's thread takes it: the domain's one enum (estop: the rig's
// e-stop, now; no motion).
using Control = domain::CampaignCommand;

// What the campaign's loop is doing now, as an operator names it (the rig panel, the safety
// matrix's states). Text only at the edges.
enum class CampaignPhase : std::uint8_t {
  none,
  arming,
  preamble,
  training,
  ramping,
  dwelling,
  retake,
  validation,
  paused,
  held,
  safing,
  shaker_check,    // the loop check before a stepped sweep: each frequency at a low level
  shaker_control,  // a control window: the base brought to its demand
  shaker_measure,  // a step's measured window
  shaker_ramp,     // between two levels, the amplitude stepped x2 a window
  shaker_sweep,    // a continuous sweep: the frequency written every cycle
  shaker_dwell,    // a resonance dwell: the frequency moved after the phase
  shaker_change    // between two steps: a glide, or a burst that moves the drive's phase
};
[[nodiscard]] const char* to_string(CampaignPhase p) noexcept;

// What a campaign ends as: text only at the JSON/database edges.
enum class CampaignEnd { none, completed, failed, aborted, interrupted };
[[nodiscard]] const char* to_string(CampaignEnd e) noexcept;
// The campaign's (and its run's) state for an end; running for none.
[[nodiscard]] domain::CampaignState state_of(CampaignEnd e) noexcept;

// A campaign as the daemon hands it to the rig's thread: the plan with the limits the rig's
// envelope allows (the tighter of the plan's and the envelope's), and for a resumed campaign
// what its earlier runs measured (their nodes, and their samples for the final fits).
struct CampaignJob {
  std::int64_t id = 0;
  double submitted_mono = 0;  // monotonic seconds at submit() (0: dispatched from the database)
  domain::Plan plan;
  std::shared_ptr<const IsolatorModel> isolator;  // a shaker's, when the daemon has a model of it (sine)
  std::vector<models::FotNode> prior_nodes;
  RunSeries prior_series;
  // A resumed campaign's last run and validation run: the tables of a resume with nothing left to
  // drive belong to them (the tables' run must exist), and the validation run's samples score them.
  std::int64_t prior_run = 0, prior_validation_run = 0;
  RunSeries prior_validation;
};

struct RunnerResult {
  CampaignEnd end = CampaignEnd::none;
  std::string reason;
  std::int64_t run_id = 0;
  // missed_deadlines: samples not taken in time. Polling the latest value, that is a loop period
  // started a whole period late (a late wake-up); with block reads, a sample lost because the
  // controller's buffer overran before it was read. Late wake-ups are counted in both modes.
  std::uint64_t samples = 0, missed_deadlines = 0, late_wakeups = 0, dropped = 0;
  std::uint64_t gaps = 0;  // holes in the run's time axis (each stored as an event)
  double longest_gap_s = 0, gap_total_s = 0;
  std::size_t nodes = 0;
  std::optional<std::int64_t> table_id, lsq_table_id;
  // The validation run (fot, when the plan asks): created with the campaign's run, its samples
  // stored under it from the first validation segment on. 0: none.
  std::int64_t validation_run_id = 0;
};

// What finishing a run needs, handed off the acquisition thread.
struct FinishJob {
  std::int64_t campaign = 0;
  domain::Plan plan;
  RunnerResult result;
  std::shared_ptr<const models::OnlineTableBuilder> builder;     // every node of the campaign (fot)
  RunSeries series;                                              // every sample of every campaign run of the campaign (fot, waveform)
  std::size_t rows_begin = 0;                                    // series[rows_begin..] came after training (loops before it are training loops)
  RunSeries validation;                                          // the validation run's samples: every table is scored on them
  std::string training_summary;                                  // what training came to (empty: no training)
  std::shared_ptr<const IsolatorModel> isolator;                 // sine: predict each point with it
  std::vector<std::pair<std::int64_t, PredictStep>> sine_steps;  // sine: each stored point's step number and what to predict
};

struct RunnerContext {
  RunnerContext(drivers::Rig& r, Supervisor& s, db::SampleWriter& w, Clock& c) : rig(r), supervisor(s), writer(w), clock(c) {}
  drivers::Rig& rig;
  Supervisor& supervisor;
  db::SampleWriter& writer;
  Clock& clock;
  double time_scale = 1.0;  // rig seconds per wall second (a time-scaled simulator)
  std::function<std::optional<Control>()> next_control = [] { return std::nullopt; };
  // The rig's stop channel (the operator's e-stop and reset, rig_worker.hpp), serviced at the top
  // of every period in every phase (arming, running, paused, safing); a latch it leaves ends the
  // campaign at once. Empty: none (tests of the loop alone).
  std::function<void(double)> service;
  const std::atomic<bool>* stop = nullptr;  // the daemon is shutting down: hold, interrupted
  double resume_preamble_after_s = 2.0;     // rig seconds of pause after which memory is re-wiped
  int watchdog_hold_periods = 20, watchdog_fail_periods = 500;
  double db_timeout_s = 10.0;                        // for the writer to create the run before arming
  std::function<std::string()> now_iso;              // wall-clock stamps for the records
  std::function<void(const std::string&)> on_state;  // observers (logs, tests)
  RigLive* live = nullptr;                           // when set, every sample and missed deadline is shown there
  std::vector<float>* loop_periods_us = nullptr;     // when set, every tick's period is recorded (benchmarks)
  // Finishing (fits, tables, the final state) off this thread; empty: done inline, then returns.
  std::function<void(FinishJob)> finish;
  // Other work off this thread, in order with finish (a descent's evaluation); empty: inline.
  std::function<void(std::function<void()>)> background;
  // The steady-clock second at which the rig's time began (the supervisor's deadlines run on it
  // across campaigns); NaN: the campaign's own start.
  double epoch = std::numeric_limits<double>::quiet_NaN();
};

// Runs the campaign (already stored as 'queued') to its end; never throws for rig errors. The
// rig is left held and disabled (idle), latched, or held where it stopped, and says why.
RunnerResult run_campaign(const CampaignJob& job, RunnerContext& ctx);

// The end of a run: the tables from every node and sample, their accuracy, and the run's and the
// campaign's final state, in one writer transaction; skipped when the run already has its tables
// (finishing is idempotent). Blocks until stored (for the finisher thread, or tests).
RunnerResult finish_campaign(FinishJob job, db::SampleWriter& writer, const std::function<std::string()>& now_iso);

}  // namespace hystlab::daemon
