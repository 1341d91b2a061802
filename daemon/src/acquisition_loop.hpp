#pragma once
// The acquisition loop's state and the strategy interface (internal to the daemon library).
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/daemon/safety.hpp"

namespace hystlab::daemon {

struct Loop;

// A campaign kind: it produces setpoints and consumes samples. The loop does everything else.
class Strategy {
 public:
  virtual ~Strategy() = default;
  // False for a resumed campaign with nothing left to drive (its tables are made from what its
  // earlier runs measured, without arming the rig).
  [[nodiscard]] virtual bool has_work() const { return true; }
  // A fresh sample, stored and checked; returns false to end the campaign (result set, or done).
  virtual bool on_frame(Loop&, const drivers::RigSample&) { return true; }
  virtual bool on_shaker(Loop&, const drivers::ShakerSample&) { return true; }
  virtual void on_pause(Loop&, double /*t*/) {}
  // After a pause (long: memory-aware) or a held link: re-issue the command in progress.
  virtual void on_resume(Loop&, double t, bool after_link_loss) = 0;
  [[nodiscard]] virtual bool done() const = 0;
  // What it is doing (the loop says paused, held and safing itself).
  [[nodiscard]] virtual CampaignPhase phase() const { return CampaignPhase::ramping; }
  virtual void fill_finish(Loop&, FinishJob&) {}
};

std::unique_ptr<Strategy> make_ramp_strategy(Loop& L);  // fot, waveform (load frame)
std::unique_ptr<Strategy> make_sine_strategy(Loop& L);  // sine (shaker)

struct Loop {
  Loop(const CampaignJob& j, RunnerContext& c);
  const CampaignJob& job;
  const domain::Plan& plan;
  RunnerContext& ctx;
  const bool shaker;
  RunnerResult result;
  SafetyEnvelope safety;
  Watchdog watchdog;
  double wall0 = 0;
  std::int64_t next_seq = 0;
  bool paused = false, link_held = false, safing = false;
  bool pause_pending = false;  // a pause asked while arming
  double pause_started = 0, answered_at = -1e300;
  double safe_deadline = 0, safe_started = 0, safe_stalled = 0;
  // Rig seconds the loop itself was not running (woken kLoopStall_s late or more): deadlines are
  // extended by it, since a paced simulator waits for its host and a starved host is no servo
  // failure (a CAN campaign "missed" δmin by 0.04 mm after 630 late wake-ups).
  double stalled = 0;
  static constexpr double kLoopStall_s = 0.02;  // of wall time: beyond any scheduling delay of a host that runs
  CampaignEnd safing_end = CampaignEnd::aborted;
  double last_t = NAN, spacing = 0;   // the time axis: the last sample's time and the expected spacing
  drivers::IoHealthSnapshot health0;  // the rig's I/O counters when the run began (the run's own are the difference)
  // The run the quality figures are gathered for, and the counters when it began: the campaign's
  // run and its validation run each get a record of their own (run_quality.cpp).
  struct RunMark {
    std::int64_t run = 0;
    std::uint64_t samples = 0, missed = 0, late = 0, dropped = 0, gaps = 0;
    double gap_total_s = 0, longest_gap_s = 0, t0 = 0;
    drivers::IoHealthSnapshot health;
  } mark;
  std::uint64_t dropped_before = 0;  // the writer's drops when the campaign began

  [[nodiscard]] double rig_time() { return (ctx.clock.now() - wall0) * ctx.time_scale; }
  // The first end wins: a trip during an abort stays an abort with both reasons said.
  void end(CampaignEnd e, const std::string& reason) {
    if (result.end != CampaignEnd::none) return;
    result.end = e;
    result.reason = reason;
  }
  void state(domain::CampaignState to, const std::string& reason);
  void event(const domain::CampaignEvent& e);
  // The safe ramp (abort or trip): the loop keeps sampling, storing and publishing until the
  // rig is within the in-position tolerance of the safe position, or holds where it stopped.
  void begin_safing(double t, CampaignEnd e, const std::string& reason, double position_mm);
  void publish(const drivers::RigSample& s);
  void publish(const drivers::ShakerSample& s);  // stored with the drive in force (drive_hz, drive_mm)
  double drive_hz = 0, drive_mm = 0;             // the shaker's drive as last commanded
  // The shaker's drive; false (result set, rig held) when the rig refused it.
  bool command_drive(double t, double f_hz, double amplitude_mm);
  void check_gap(double t);
  void show_phase(CampaignPhase p) noexcept {
    if (ctx.live) ctx.live->phase.store(static_cast<std::uint8_t>(p), std::memory_order_relaxed);
  }
  // A command the rig did not take. A lost answer (timeout, dropped link) holds the rig like a
  // lost read, and the segment is commanded again when the rig answers; true while the campaign
  // goes on. Any other refusal, or kMaxLostCommands in a row, holds and fails it.
  bool command_failed(double t, std::error_code ec, const char* what);
  void command_taken() noexcept { lost_commands = 0; }
  static constexpr int kMaxLostCommands = 3;
  int lost_commands = 0;
};

// From here on the quality figures belong to `run` (the campaign's run, then its validation run).
void mark_run(Loop& L, std::int64_t run);
// The figures since mark_run, stored as the run's "quality" event: samples, missed deadlines,
// late wake-ups, samples dropped or lost by the controller's buffer, I/O errors and reconnects,
// holes in the time axis, and the rate stored in rig time.
void record_quality(Loop& L);

}  // namespace hystlab::daemon
