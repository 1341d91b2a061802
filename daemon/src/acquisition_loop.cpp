// The one acquisition loop: arming handshake, absolute deadlines, controls, supervision of every
// status bit, the safety envelope, the watchdog, gap accounting, the safe ramp, and hand-off of
// the finished run. Campaign kinds are strategies (ramp_strategy.cpp, sine_strategy.cpp).
// Here: the Loop's services to the strategies; the run's start and end: acquisition_run.cpp; its
// periods: acquisition_tick.cpp.
#include <algorithm>
#include <cmath>
#include <string>
#include <system_error>

#include "acquisition_loop.hpp"

namespace hystlab::daemon {

domain::CampaignState state_of(CampaignEnd e) noexcept {
  switch (e) {
    case CampaignEnd::completed:
      return domain::CampaignState::completed;
    case CampaignEnd::failed:
      return domain::CampaignState::failed;
    case CampaignEnd::aborted:
      return domain::CampaignState::aborted;
    case CampaignEnd::interrupted:
      return domain::CampaignState::interrupted;
    case CampaignEnd::none:
      break;
  }
  return domain::CampaignState::running;
}

const char* to_string(CampaignEnd e) noexcept { return domain::to_string(state_of(e)); }

const char* to_string(CampaignPhase p) noexcept {
  using P = CampaignPhase;
  switch (p) {
    case P::none:
      return "none";
    case P::arming:
      return "arming";
    case P::preamble:
      return "preamble";
    case P::training:
      return "training";
    case P::ramping:
      return "ramping";
    case P::dwelling:
      return "dwelling";
    case P::retake:
      return "retake";
    case P::validation:
      return "validation";
    case P::paused:
      return "paused";
    case P::held:
      return "held";
    case P::safing:
      return "safing";
    case P::shaker_check:
      return "shaker_check";
    case P::shaker_control:
      return "shaker_control";
    case P::shaker_measure:
      return "shaker_measure";
    case P::shaker_ramp:
      return "shaker_ramp";
    case P::shaker_sweep:
      return "shaker_sweep";
    case P::shaker_dwell:
      return "shaker_dwell";
    case P::shaker_change:
      return "shaker_change";
  }
  return "?";
}

Loop::Loop(const CampaignJob& j, RunnerContext& c)
    : job(j),
      plan(j.plan),
      ctx(c),
      shaker(j.plan.kind == domain::CampaignKind::sine),
      safety(j.plan.limits),
      watchdog(c.watchdog_hold_periods, c.watchdog_fail_periods),
      health0(c.rig.health()) {}

void Loop::state(domain::CampaignState to, const std::string& reason) {
  const std::string now = ctx.now_iso();
  const auto id = job.id;
  ctx.writer.post([id, to, reason, now](db::Store& s) { s.transition(id, to, reason, now); });
  if (ctx.on_state) ctx.on_state(domain::to_string(to));
}

void Loop::event(const domain::CampaignEvent& e) {
  const std::string now = ctx.now_iso();
  const auto id = job.id;
  ctx.writer.post([id, e, now](db::Store& s) { s.add_event(id, e, now); });
}

void Loop::publish(const drivers::RigSample& s) {
  ctx.writer.try_push(db::SampleRow{result.run_id, next_seq++, s.time_s, s.command_mm, s.displacement_mm, s.force_N, s.status_word});
  ++result.samples;
  if (ctx.live) {
    ctx.live->ring.push(
        LiveSample::of(ctx.clock.now(), s.time_s, domain::FrameSample{s.command_mm, s.displacement_mm, s.force_N}, result.run_id, s.status_word));
    ctx.live->samples.fetch_add(1, std::memory_order_relaxed);
  }
}

void Loop::publish(const drivers::ShakerSample& s) {
  db::ShakerRow row{result.run_id,
                    next_seq++,
                    s.time_s,
                    {drive_hz, drive_mm, s.base_displacement_mm, s.mass_displacement_mm, s.base_accel_m_s2, s.mass_accel_m_s2},
                    s.status_word};
  ctx.writer.try_push(row);
  ++result.samples;
  if (ctx.live) {
    ctx.live->ring.push(LiveSample::of(ctx.clock.now(), s.time_s, domain::LiveShaker{s.base_displacement_mm, s.mass_displacement_mm, s.mass_accel_m_s2},
                                       result.run_id, s.status_word));
    ctx.live->samples.fetch_add(1, std::memory_order_relaxed);
  }
}

bool Loop::command_drive(double t, double f_hz, double amplitude_mm) {
  // As the load frame's commands: a lost answer (a busy controller answering late, a dropped
  // link) holds the table and the step is taken again when the rig answers, kMaxLostCommands in
  // a row fail the campaign; a refusal fails it at once (stop 31: one late answer ended a sweep).
  if (auto ec = ctx.rig.command_shaker(f_hz, amplitude_mm, true)) {
    (void)command_failed(t, ec, "shaker command");
    return false;
  }
  command_taken();
  drive_hz = f_hz;
  drive_mm = amplitude_mm;
  return true;
}

// A hole in the time axis (a lost link, a frozen sensor, a stall, a reconnect): counted always,
// stored as an event when longer than 20 ms, summed up when the campaign ends.
void Loop::check_gap(double t) {
  const double dt = t - last_t;
  last_t = t;
  if (!(dt > 3 * spacing && dt > 0.005)) return;
  const double hole = dt - spacing;
  ++result.gaps;
  result.gap_total_s += hole;
  result.longest_gap_s = std::max(result.longest_gap_s, hole);
  mark.longest_gap_s = std::max(mark.longest_gap_s, hole);
  if (hole > 0.02) event(domain::GapEvent{t - dt, t, hole * 1e3});
}

void Loop::begin_safing(double t, CampaignEnd e, const std::string& reason, double x) {
  end(e, reason);
  if (safing) return;
  if (shaker) {  // a shaker's safe state is no drive
    ctx.supervisor.hold(t, reason);
    return;
  }
  safing = true;
  safe_started = t;
  safe_stalled = stalled;
  const domain::Limits& l = plan.limits;
  const domain::SupervisionSettings& s = ctx.supervisor.settings();
  safe_deadline = t + std::fabs(x - l.safe_position_mm) / l.safe_rate_mm_s + s.lag_s + s.settle_s + domain::kHostStallAllowance_s * ctx.time_scale;
  ctx.supervisor.begin_safing(t, reason + ": to the safe position");
  if (auto ec = ctx.rig.command(l.safe_position_mm, l.safe_rate_mm_s)) {
    ctx.supervisor.hold(t, "the safe ramp was refused: held");
    result.reason += "; the safe ramp was refused (" + ec.message() + "): held where it stopped";
    safing = false;
  }
}

bool Loop::command_failed(double t, std::error_code ec, const char* what) {
  using drivers::RigError;
  const bool lost = ec == RigError::timeout || ec == RigError::connection_lost || ec == RigError::not_connected || ec == RigError::crc_error;
  if (lost && ++lost_commands < kMaxLostCommands) {
    link_held = true;
    ctx.supervisor.on_link_error(t, ec);
    ctx.supervisor.hold(t, std::string(what) + " lost: held until the rig answers");
    return true;
  }
  ctx.supervisor.hold(t, std::string(what) + " refused: held");
  end(CampaignEnd::failed,
      std::string(what) + " refused: " + ec.message() + (lost ? " (" + std::to_string(lost_commands) + " times in a row)" : std::string()));
  return false;
}

}  // namespace hystlab::daemon
