// The acquisition loop's periods (run_ticks): absolute deadlines, the operator's controls, each
// fresh sample supervised, checked against the safety envelope and given to the strategy, the
// watchdog for reads that bring nothing new, and the end of the safe ramp.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <system_error>
#include <vector>

#include "acquisition_tick.hpp"

namespace hystlab::daemon {

StatusView view_of(const drivers::RigSample& s) { return {s.status_word, s.fault_code, s.displacement_mm}; }
StatusView view_of(const drivers::ShakerSample& s) { return {s.status_word, s.fault_code, 0.0}; }

namespace {
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
}  // namespace

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

}  // namespace hystlab::daemon
