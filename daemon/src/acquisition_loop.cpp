// The one acquisition loop: arming handshake, absolute deadlines, controls, supervision of every
// status bit, the safety envelope, the watchdog, gap accounting, the safe ramp, and hand-off of
// the finished run. Campaign kinds are strategies (ramp_strategy.cpp, sine_strategy.cpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

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

namespace {
StatusView view_of(const drivers::RigSample& s) { return {s.status_word, s.fault_code, s.displacement_mm}; }
StatusView view_of(const drivers::ShakerSample& s) { return {s.status_word, s.fault_code, 0.0}; }

// The arming handshake, sampled at the plan's period; false (result set) when it fails.
bool arm(Loop& L) {
  RunnerContext& c = L.ctx;
  const double period = 1.0 / L.plan.sample_rate_hz;
  double next = c.clock.now();
  // A rig that does not answer for 2 s plus the arming timeout is not armed (on a time-scaled rig
  // at least the host-stall allowance of wall time: 3 s of rig time is 15 ms at scale 200).
  const double give_up =
      L.rig_time() + std::max(2.0 + c.supervisor.settings().arm_timeout_s, c.time_scale > 1 ? domain::kHostStallAllowance_s * c.time_scale : 0.0);
  bool begun = false;
  (void)c.rig.connect(L.rig_time());
  for (;;) {
    next += period;
    c.clock.sleep_until(next);
    const double t = L.rig_time();
    if (c.stop && c.stop->load()) return L.end(CampaignEnd::interrupted, "the daemon is stopping"), c.supervisor.disarm(t, "stopping"), false;
    L.show_phase(CampaignPhase::arming);
    const bool was_latched = c.supervisor.latched();  // a latch from before fails the handshake below, named
    if (c.service) c.service(t);
    if (!was_latched && c.supervisor.latched()) return L.end(CampaignEnd::aborted, c.supervisor.latch_reason() + " while arming"), false;
    c.supervisor.heartbeat(c.clock.now());
    const auto ctl = c.next_control();
    if (ctl && (*ctl == Control::pause || *ctl == Control::resume)) L.pause_pending = *ctl == Control::pause;  // applied once armed
    if (ctl && (*ctl == Control::abort || *ctl == Control::estop)) {
      if (*ctl == Control::estop)
        c.supervisor.estop(t, "e-stop by the operator");
      else
        c.supervisor.disarm(t, "aborted while arming");
      return L.end(CampaignEnd::aborted, *ctl == Control::estop ? "e-stop by the operator" : "aborted by the operator while arming"), false;
    }
    StatusView v;
    std::error_code ec;
    if (L.shaker) {
      drivers::ShakerSample s;
      ec = c.rig.read_shaker(t, s);
      v = view_of(s);
    } else {
      drivers::RigSample s;
      ec = c.rig.read_sample(t, s);
      v = view_of(s);
    }
    if (ec == drivers::RigError::unsupported)
      return L.end(CampaignEnd::failed,
                   std::string("a ") + domain::to_string(L.plan.kind) + " campaign needs a " + (L.shaker ? "shaker" : "load frame") + "; this rig is not one"),
             false;
    if (ec) {
      c.supervisor.on_link_error(t, ec);
      if (t > give_up) return L.end(CampaignEnd::failed, "cannot arm: the rig does not answer (" + ec.message() + ")"), false;
      continue;
    }
    (void)c.supervisor.on_status(t, v);
    if (!begun) {
      if (c.supervisor.state() == RigState::disconnected) continue;  // re-asserting first
      if (auto why = c.supervisor.begin_arming(t)) return L.end(CampaignEnd::failed, "cannot arm: " + *why), false;
      begun = true;
    }
    std::string why;
    const auto r = c.supervisor.arming_step(t, v, why);
    if (r == Supervisor::Arming::armed) return true;
    if (r == Supervisor::Arming::failed) return L.end(CampaignEnd::failed, "cannot arm: " + why), false;
  }
}

void pause_now(Loop& L, Strategy& strategy, double t) {
  L.ctx.supervisor.hold(t, "paused by the operator");
  strategy.on_pause(L, t);
  L.paused = true;
  L.pause_started = t;
  L.state(domain::CampaignState::paused, "operator");
}

// The rig's latch ends the campaign at once, whatever it was doing: a safe ramp under way keeps
// its end (aborted) and says that the e-stop came on top of it.
bool latched_end(Loop& L) {
  const Supervisor& sup = L.ctx.supervisor;
  if (!sup.latched()) return false;
  if (L.result.end == CampaignEnd::none)
    L.end(CampaignEnd::aborted, sup.latch_reason());
  else if (L.result.reason.find(sup.latch_reason()) == std::string::npos)
    L.result.reason += "; then " + sup.latch_reason();
  L.safing = false;
  return true;
}

// The stop channel, then pause, resume, abort, e-stop; false when the campaign ends at once.
bool handle_control(Loop& L, Strategy& strategy, double t, double x) {
  Supervisor& sup = L.ctx.supervisor;
  if (L.ctx.service) L.ctx.service(t);
  if (latched_end(L)) return false;
  const auto c = L.ctx.next_control();
  if (!c) return true;
  if (*c == Control::estop) {
    (void)sup.estop(t, "e-stop by the operator");
    return !latched_end(L);
  }
  if (*c == Control::abort) {
    L.paused = false;
    L.begin_safing(t, CampaignEnd::aborted, "aborted by the operator", x);
    return !L.shaker;
  }
  if (L.safing) return true;  // pause and resume mean nothing on the way to the safe position
  if (*c == Control::pause && !L.paused) {
    pause_now(L, strategy, t);
  } else if (*c == Control::resume && L.paused) {
    sup.release(t, "resumed by the operator");
    if (sup.state() != RigState::armed) return true;  // still held (the link): resumed when it answers
    L.paused = false;
    strategy.on_resume(L, t, false);
    return L.result.end == CampaignEnd::none;  // the resumed step's command refused: ended there
  }
  return true;
}

// The safe ramp's end: arrived within the in-position tolerance, or held where it stopped.
bool safing_step(Loop& L, double t, double x) {
  const domain::Limits& l = L.plan.limits;
  const double tol = L.ctx.supervisor.settings().in_position_mm;
  if (std::fabs(x - l.safe_position_mm) <= tol) {
    L.event(domain::SafeEvent{x, l.safe_position_mm, t - L.safe_started});
    return false;
  }
  if (t > L.safe_deadline + (L.stalled - L.safe_stalled)) {
    L.ctx.supervisor.hold(t, "the safe position was not reached: held");
    char buf[160];
    std::snprintf(buf, sizeof buf, "; the safe position %.3f mm was not reached in %.1f s: held at %.3f mm", l.safe_position_mm, t - L.safe_started, x);
    L.result.reason += buf;
    return false;
  }
  return true;
}

// One fresh load-frame sample; false when the campaign ends.
bool frame_sample(Loop& L, Strategy& strategy, const drivers::RigSample& s) {
  L.check_gap(s.time_s);
  L.publish(s);
  if (auto why = L.ctx.supervisor.on_status(s.time_s, view_of(s))) {
    L.end(CampaignEnd::failed, *why + (L.safing ? " (on the way to the safe position)" : ""));
    L.safing = false;
    return false;
  }
  if (L.safing) return safing_step(L, s.time_s, s.displacement_mm);
  if (auto trip = L.safety.check(s.displacement_mm, s.force_N, s.time_s, std::max(s.time_s, L.answered_at))) {
    L.begin_safing(s.time_s, CampaignEnd::aborted, "safety trip: " + *trip, s.displacement_mm);
    return L.safing;
  }
  if (L.paused || L.link_held) return true;
  return strategy.on_frame(L, s);
}

bool shaker_sample(Loop& L, Strategy& strategy, const drivers::ShakerSample& s) {
  L.check_gap(s.time_s);
  L.publish(s);
  if (auto why = L.ctx.supervisor.on_status(s.time_s, view_of(s))) return L.end(CampaignEnd::failed, *why), false;
  if (std::fabs(s.mass_displacement_mm) > L.plan.limits.displacement_max_mm) {
    L.begin_safing(s.time_s, CampaignEnd::aborted, "safety trip: mass displacement beyond the limits", 0.0);
    return false;
  }
  if (L.paused || L.link_held) return true;
  return strategy.on_shaker(L, s);
}

// A read that brought nothing fresh: the watchdog decides between waiting, holding and failing.
bool on_missed(Loop& L, double t, std::error_code ec) {
  const auto v = L.watchdog.missed();
  if (v == Watchdog::Verdict::hold && !L.link_held) {
    L.link_held = true;
    L.ctx.supervisor.on_link_error(t, ec);
    L.ctx.supervisor.hold(t, "no fresh sample: held");
  }
  if (v != Watchdog::Verdict::fail) return true;
  L.ctx.supervisor.hold(t, "watchdog: held");
  L.end(CampaignEnd::failed, "watchdog: no fresh sample for " + std::to_string(L.watchdog.missed_periods()) + " periods (" + ec.message() +
                                 "); the rig is held, and held again the moment it answers");
  L.safing = false;
  return false;
}

void count_tick(Loop& L, double now, double next, double period, bool blocks) {
  if (now - next <= period) return;
  ++L.result.late_wakeups;
  if (L.ctx.live) L.ctx.live->late_wakeups.fetch_add(1, std::memory_order_relaxed);
  if (blocks) return;  // block reads lose nothing to a late wake-up
  ++L.result.missed_deadlines;
  if (L.ctx.live) L.ctx.live->missed_deadlines.fetch_add(1, std::memory_order_relaxed);
}

struct Reader {  // the rig's samples, fresh ones only, at the plan's rate on the controller's clock
  std::vector<drivers::RigSample> block;
  std::vector<drivers::ShakerSample> shaker_block;
  std::uint32_t last_counter = 0;
  bool have_counter = false;
  double last_kept = -1e300;
  Reader() {  // the rig fills them without allocating
    block.reserve(4096);
    shaker_block.reserve(4096);
  }
  bool fresh(std::uint32_t counter) {
    if (have_counter && counter == last_counter) return false;
    have_counter = true;
    last_counter = counter;
    return true;
  }
};

// A fresh sample while the link was held (a lost read or a lost command): once the hold is
// re-asserted and released, the strategy takes its segment or step again (resumed at resume_t);
// false when that ended the campaign (its command refused again).
bool link_back(Loop& L, Strategy& strategy, double sample_t, double resume_t, const StatusView& v, const char* what) {
  if (!L.link_held) return true;
  if (L.paused || L.safing) return L.link_held = false, true;
  Supervisor& sup = L.ctx.supervisor;
  (void)sup.on_status(sample_t, v);
  sup.release(sample_t, std::string("link back: the ") + what + " is taken again");
  if (sup.state() == RigState::armed) L.link_held = false, strategy.on_resume(L, resume_t, true);
  return L.result.end == CampaignEnd::none;
}

// One tick's reading and processing; false when the campaign ends.
bool tick(Loop& L, Strategy& strategy, Reader& rd, double t, bool blocks, double period) {
  RunnerContext& c = L.ctx;
  bool fresh = false;
  if (L.shaker) {  // time_s is the rig's: on the controller's clock when its map gives one
    if (auto ec = c.rig.read_shaker_samples(t, rd.shaker_block)) return on_missed(L, t, ec);
    for (const drivers::ShakerSample& s : rd.shaker_block) {
      if (!rd.fresh(s.sample_counter)) continue;
      fresh = true;
      if (blocks && s.time_s - rd.last_kept < period * c.time_scale * (1 - 1e-6)) continue;  // a faster controller
      rd.last_kept = s.time_s;
      if (!link_back(L, strategy, s.time_s, blocks ? s.time_s : t, view_of(s), "step")) return false;
      if (!shaker_sample(L, strategy, s)) return false;
      if (strategy.done()) break;  // a block's later samples belong to no step: the campaign is over
    }
  } else {
    if (auto ec = c.rig.read_samples(t, rd.block)) return on_missed(L, t, ec);
    if (!blocks) L.answered_at = L.rig_time();  // a polled sample is stamped when asked
    for (const drivers::RigSample& s : rd.block) {
      if (!rd.fresh(s.sample_counter)) continue;
      fresh = true;
      if (blocks && s.time_s - rd.last_kept < period * c.time_scale * (1 - 1e-6)) continue;  // a faster controller
      rd.last_kept = s.time_s;
      if (!link_back(L, strategy, s.time_s, s.time_s, view_of(s), "segment")) return false;
      if (!frame_sample(L, strategy, s)) return false;
    }
  }
  if (!fresh) return on_missed(L, t, drivers::RigError::stale_data);
  L.watchdog.fresh();
  if (strategy.done() && !L.safing) {
    L.end(CampaignEnd::completed, "");
    return false;
  }
  return true;
}

void run_ticks(Loop& L, Strategy& strategy) {
  RunnerContext& c = L.ctx;
  // The plan's rate is in rig time: a rig slowed down (time scale under 1, a simulator in slow
  // motion) is polled as much slower, or 3 of 4 reads would find nothing new at time scale 0.25
  // and the watchdog would take that for a silent rig. A faster rig is polled at the plan's rate.
  const double period = 1.0 / (L.plan.sample_rate_hz * std::min(1.0, c.time_scale));
  const bool blocks = c.rig.block_reads();
  const std::uint64_t lost_before = c.rig.health().lost_samples;
  L.spacing = period * c.time_scale;
  Reader rd;
  double next = c.clock.now(), prev_tick = 0;
  if (L.pause_pending) pause_now(L, strategy, L.rig_time());  // asked while arming: paused the moment it is armed
  for (;;) {
    next += period;
    c.clock.sleep_until(next);
    const double now = c.clock.now();
    count_tick(L, now, next, period, blocks);
    // Woken far behind (a starved host): the ticks missed are gone, not to be run back to back;
    // a burst would read nothing fresh and count as a silent rig for the watchdog.
    if (now - next > 5 * period) {
      if (now - next > Loop::kLoopStall_s) L.stalled += (now - next) * c.time_scale;
      next = now;
    }
    if (c.loop_periods_us && prev_tick > 0) c.loop_periods_us->push_back(static_cast<float>((now - prev_tick) * 1e6));
    prev_tick = now;
    const double t = (now - L.wall0) * c.time_scale;
    c.supervisor.heartbeat(now);
    if (c.stop && c.stop->load()) {
      L.end(CampaignEnd::interrupted, "the daemon is stopping");
      break;
    }
    const double x = rd.block.empty() ? 0.0 : rd.block.back().displacement_mm;
    L.show_phase(L.safing ? CampaignPhase::safing : L.paused ? CampaignPhase::paused : L.link_held ? CampaignPhase::held : strategy.phase());
    if (!handle_control(L, strategy, t, x)) break;
    const bool going = tick(L, strategy, rd, t, blocks, period);
    if (blocks) {
      const std::uint64_t lost = c.rig.health().lost_samples - lost_before;
      if (c.live && lost > L.result.missed_deadlines) c.live->missed_deadlines.fetch_add(lost - L.result.missed_deadlines);
      L.result.missed_deadlines = lost;
    }
    if (!going) break;
  }
}

// The rig after the run: held and disabled (idle) unless latched; a lost link re-asserts it later.
void leave_rig(Loop& L) {
  const double t = L.rig_time();
  Supervisor& sup = L.ctx.supervisor;
  if (sup.latched()) return;
  if (L.shaker) (void)L.ctx.rig.command_shaker(0.0, 0.0, false);
  sup.disarm(t, std::string("campaign ") + to_string(L.result.end) + (L.result.reason.empty() ? "" : ": " + L.result.reason));
}

// drove: the loop ran on the rig (a resume with nothing left to drive has no quality of its own).
void hand_off(Loop& L, Strategy& strategy, bool drove = true) {
  FinishJob fj;
  fj.campaign = L.job.id;
  fj.plan = L.plan;
  strategy.fill_finish(L, fj);  // first: the last descent's bottom node is counted there
  if (fj.validation.empty() && !L.job.prior_validation.empty()) fj.validation = L.job.prior_validation;  // its chunks shared: O(chunks)
  fj.result = L.result;
  if (L.result.gaps > 0) L.event(domain::GapsEvent{static_cast<std::int64_t>(L.result.gaps), L.result.gap_total_s * 1e3, L.result.longest_gap_s * 1e3});
  if (drove) record_quality(L);
  if (L.ctx.finish) {
    L.ctx.finish(std::move(fj));
    return;
  }
  L.result = finish_campaign(std::move(fj), L.ctx.writer, L.ctx.now_iso);
  if (L.ctx.on_state) L.ctx.on_state(to_string(L.result.end));
}

// The run, and the validation run beside it when the plan has one (created now, so that starting
// it later is no database round trip on the acquisition thread).
bool create_run(Loop& L) {
  const auto id = L.job.id;
  const std::string now = L.ctx.now_iso();
  const double wall = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count(), mono = L.wall0;
  const bool validation = L.plan.kind == domain::CampaignKind::fot && L.plan.validation.enabled;
  const auto runs = L.ctx.writer.call<std::pair<std::int64_t, std::int64_t>>(
      [id, now, wall, mono, validation](db::Store& s) { return s.add_runs(id, now, wall, mono, validation); }, L.ctx.db_timeout_s);
  if (!runs) return L.end(CampaignEnd::failed, "the database did not take the new run in time: the rig was not armed"), false;
  L.result.run_id = runs->first;
  L.result.validation_run_id = runs->second;
  return true;
}
}  // namespace

RunnerResult run_campaign(const CampaignJob& job, RunnerContext& ctx) {
  Loop L(job, ctx);
  std::unique_ptr<Strategy> strategy = L.shaker ? make_sine_strategy(L) : make_ramp_strategy(L);
  L.wall0 = ctx.clock.now();
  ctx.supervisor.set_time_scale(ctx.time_scale);
  ctx.supervisor.set_time_offset(std::isnan(ctx.epoch) ? 0.0 : (L.wall0 - ctx.epoch) * ctx.time_scale);
  const domain::Limits& l = job.plan.limits;
  L.event(domain::LimitsEvent{{l.displacement_min_mm, l.displacement_max_mm},
                              l.force_max_N,
                              l.rate_max_mm_s,
                              l.safe_position_mm,
                              l.safe_rate_mm_s,
                              ctx.supervisor.settings().in_position_mm});
  if (!strategy->has_work()) {  // a resume with every node measured: finish without moving
    L.end(CampaignEnd::completed, "every node was measured by earlier runs: finished without driving the rig");
    L.result.run_id = job.prior_run;  // the tables belong to the last run that measured (it exists)
    hand_off(L, *strategy, false);
    return L.result;
  }
  L.state(domain::CampaignState::arming, "started by the daemon");
  L.dropped_before = ctx.writer.stats().dropped_full;
  if (create_run(L) && (mark_run(L, L.result.run_id), arm(L))) {
    L.state(domain::CampaignState::running, "armed");
    run_ticks(L, *strategy);
  }
  L.show_phase(CampaignPhase::none);
  leave_rig(L);
  L.result.dropped = ctx.writer.stats().dropped_full - L.dropped_before;
  if (L.result.gaps > 0 && L.result.end == CampaignEnd::completed)
    L.result.reason =
        std::to_string(L.result.gaps) + " gap(s) in the data, the longest " + std::to_string(static_cast<int>(L.result.longest_gap_s * 1e3)) + " ms";
  hand_off(L, *strategy);
  ctx.supervisor.set_time_offset(0.0);
  return L.result;
}

}  // namespace hystlab::daemon
