#include "hystlab/daemon/campaign_runner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include "hystlab/daemon/online_fot.hpp"
#include "hystlab/daemon/safety.hpp"
#include "hystlab/daemon/sequencer.hpp"
#include "hystlab/models/online_table_builder.hpp"
#include "monotonic_clock.hpp"
#include "run_finish.hpp"

namespace hystlab::daemon {
namespace {
using drivers::RigError;

// The loop's state: everything one tick needs, in one place.
struct Loop {
  const Plan& plan;
  RunnerContext& ctx;
  std::int64_t campaign, run;
  Sequencer seq;
  SafetyEnvelope safety;
  Watchdog watchdog;
  std::shared_ptr<models::OnlineTableBuilder> builder;
  std::unique_ptr<OnlineFot> fot;
  RunSeries series;
  RunnerResult result;
  std::int64_t next_seq = 0;
  std::uint32_t last_counter = 0;
  bool have_counter = false, paused = false, watchdog_holding = false;
  double pause_started = 0;
  double answered_at = -1e300;  // polling: when the last read's answer came (rig seconds)

  void state(const std::string& to, const std::string& reason) {
    const std::string now = ctx.now_iso();
    const auto id = campaign;
    ctx.writer.post([id, to, reason, now](db::Store& s) { s.transition(id, to, reason, now); });
    if (ctx.on_state) ctx.on_state(to);
  }
  bool collecting() const {
    const Segment* s = seq.current();
    return s && (s->kind == SegmentKind::rise || s->kind == SegmentKind::descent);
  }
};

// Drives to the safe position at the safe rate, sampling, for a bounded time.
void go_safe(Loop& L, double wall0) {
  const Limits& l = L.plan.limits;
  (void)L.ctx.rig.hold(false);
  (void)L.ctx.rig.command(l.safe_position_mm, l.safe_rate_mm_s);
  drivers::RigSample s;
  const double deadline = mono_now() + 5.0 + 2.0 * (l.displacement_max_mm - l.displacement_min_mm) / l.safe_rate_mm_s / L.ctx.time_scale;
  while (mono_now() < deadline) {
    if (!L.ctx.rig.read_sample((mono_now() - wall0) * L.ctx.time_scale, s)) {
      L.ctx.writer.try_push({L.run, L.next_seq++, s.time_s, s.command_mm, s.displacement_mm, s.force_N, s.status_word});
      if (std::fabs(s.displacement_mm - l.safe_position_mm) < 0.01 * (l.displacement_max_mm - l.displacement_min_mm)) break;
    }
    sleep_until(mono_now() + 1.0 / L.plan.sample_rate_hz);
  }
  (void)L.ctx.rig.hold(true);
}

// Handles pause/resume/abort; returns false when the campaign ends here.
bool handle_control(Loop& L, double t, double wall0) {
  const auto c = L.ctx.next_control();
  if (!c) return true;
  if (*c == Control::pause && !L.paused) {
    (void)L.ctx.rig.hold(true);
    L.paused = true;
    L.pause_started = t;
    L.state("paused", "operator");
  } else if (*c == Control::resume && L.paused) {
    L.paused = false;
    const Segment* cur = L.seq.current();
    if (L.plan.kind == "fot" && cur && t - L.pause_started > L.ctx.resume_preamble_after_s) {
      // Memory-aware resume: the specimen drifted while held; wipe its memory at δmin and
      // re-take the row that was in progress.
      const std::size_t k = cur->kind == SegmentKind::descent ? L.seq.index() - 1 : L.seq.index();
      L.seq.restart_at(k);
      L.seq.insert_before_current({{L.plan.lo_mm, L.plan.ramp_rate_mm_s, L.plan.dwell_s, SegmentKind::preamble, 0}});
      L.state("running", "resumed after a long pause: wipe-out preamble to δmin, row re-taken");
    } else {
      L.seq.restart_at(L.seq.index());  // re-issue the current segment's command
      L.state("running", "resumed");
    }
    (void)L.ctx.rig.hold(false);
  } else if (*c == Control::estop) {
    (void)L.ctx.rig.estop(true);  // passed straight to the rig: it holds where it is
    L.result.reason = "e-stop by the operator";
    L.result.state = "aborted";
    return false;
  } else if (*c == Control::abort) {
    L.result.reason = "aborted by the operator";
    go_safe(L, wall0);
    L.result.state = "aborted";
    return false;
  }
  return true;
}

// One sample: store it, check safety, step the input and the online fit. False when it ends.
bool on_sample(Loop& L, const drivers::RigSample& s, double wall0) {
  L.ctx.writer.try_push({L.run, L.next_seq++, s.time_s, s.command_mm, s.displacement_mm, s.force_N, s.status_word});
  L.series.add(s.displacement_mm, s.force_N);
  ++L.result.samples;
  if (RigLive* live = L.ctx.live) {
    live->ring.push({mono_now(), s.time_s, s.command_mm, s.displacement_mm, s.force_N, L.run, s.status_word});
    live->samples.fetch_add(1, std::memory_order_relaxed);
  }
  if (auto trip = L.safety.check(s.displacement_mm, s.force_N, s.time_s, std::max(s.time_s, L.answered_at))) {
    L.result.reason = "safety trip: " + *trip;
    go_safe(L, wall0);
    L.result.state = "aborted";
    return false;
  }
  if ((s.status_word & 0x8U) != 0) {  // the rig's own e-stop
    L.result.reason = "e-stop pressed on the rig";
    L.result.state = "aborted";
    return false;
  }
  if (L.paused) return true;
  if (const auto cmd = L.seq.step(s.time_s, s.displacement_mm)) {
    if (auto ec = L.ctx.rig.command(cmd->target_mm, cmd->rate_mm_s)) {
      L.result.reason = "command refused: " + ec.message();
      L.result.state = "failed";
      return false;
    }
  }
  if (L.fot) {
    L.fot->feed(s.time_s, s.displacement_mm, s.force_N, L.collecting());
    if (L.fot->take_descent_completed()) post_evaluation(L.ctx.writer, L.campaign, *L.builder, L.series, L.ctx.now_iso());
  }
  return true;
}

// Block reads: a sample the controller's buffer lost before it was read is a missed deadline.
void count_lost(Loop& L, std::uint64_t lost_before) {
  const std::uint64_t lost = L.ctx.rig.health().lost_samples - lost_before;
  if (lost == L.result.missed_deadlines) return;
  if (L.ctx.live) L.ctx.live->missed_deadlines.fetch_add(lost - L.result.missed_deadlines, std::memory_order_relaxed);
  L.result.missed_deadlines = lost;
}

// A failed read: the watchdog decides between waiting, holding and failing.
bool on_missed(Loop& L, std::error_code ec) {
  const auto v = L.watchdog.missed();
  if (v == Watchdog::Verdict::hold && !L.watchdog_holding) {
    L.watchdog_holding = true;
    (void)L.ctx.rig.hold(true);
  }
  if (v == Watchdog::Verdict::fail) {
    (void)L.ctx.rig.hold(true);
    L.result.reason = "watchdog: no fresh sample for " + std::to_string(L.watchdog.missed_periods()) +
                      " periods (" + ec.message() + "); holding rather than guessing";
    L.result.state = "failed";
    return false;
  }
  return true;
}
}  // namespace

RunnerResult run_campaign(std::int64_t campaign_id, const Plan& plan, RunnerContext& ctx) {
  if (plan.kind == "sine") return run_sine_campaign(campaign_id, plan, ctx);
  const std::vector<Segment> schedule = plan.kind == "fot" ? fot_schedule(plan) : waveform_schedule(plan);
  const double tol = std::max(0.002 * (plan.hi_mm - plan.lo_mm), 0.002);
  Loop L{plan, ctx, campaign_id, 0, Sequencer(schedule, tol), SafetyEnvelope(plan.limits),
         Watchdog(ctx.watchdog_hold_periods, ctx.watchdog_fail_periods), nullptr, nullptr, {}, {}};
  L.state("arming", "started by the daemon");
  const double wall0 = mono_now();
  const std::uint64_t dropped_before = ctx.writer.stats().dropped_full;  // the writer outlives campaigns
  if (auto ec = ctx.rig.connect(0.0); ec && ec != RigError::not_connected) {
    L.result.state = "failed";
    L.result.reason = "cannot connect to the rig: " + ec.message();
    L.state("failed", L.result.reason);
    return L.result;
  }
  (void)ctx.rig.hold(false);
  if (auto ec = ctx.rig.arm(true)) {
    L.result.state = "failed";
    L.result.reason = "cannot arm the rig: " + ec.message();
    L.state("failed", L.result.reason);
    return L.result;
  }
  L.run = L.result.run_id = ctx.store.add_run(campaign_id, ctx.now_iso(), wall_now(), wall0);
  if (plan.kind == "fot") {
    const models::Grid g = models::Grid::make(plan.lo_mm, plan.hi_mm, plan.subdivisions);
    L.builder = std::make_shared<models::OnlineTableBuilder>(g);
    const double band = std::min(0.05 * g.step(), 0.02);
    for (const models::FotNode& n : ctx.prior_nodes) (void)L.builder->add(n);
    if (!ctx.prior_nodes.empty()) {  // resume: drive only the rows not yet complete
      std::vector<Segment> rest{schedule.front()};
      for (const Segment& seg : schedule) {
        if (seg.kind != SegmentKind::rise && seg.kind != SegmentKind::descent) continue;
        bool row_done = true;
        for (int j = 0; j < seg.row; ++j) row_done = row_done && L.builder->identified(seg.row, j);
        if (!row_done) rest.push_back(seg);
      }
      L.seq = Sequencer(rest, tol);
    }
    L.fot = std::make_unique<OnlineFot>(g, band, [&L](const models::FotNode& n, double t) {
      if (L.builder->add(n)) return;
      ++L.result.nodes;
      const auto run = L.run;
      L.ctx.writer.post([run, n, t](db::Store& s) { s.add_fot_node(run, n.alpha, n.beta, n.force_alpha, n.force_alpha_beta, t); });
    });
  }
  L.state("running", "armed");
  const double period = 1.0 / plan.sample_rate_hz;
  const bool blocks = ctx.rig.block_reads();
  const std::uint64_t lost_before = ctx.rig.health().lost_samples;
  double next = mono_now();
  std::vector<drivers::RigSample> block;
  block.reserve(4096);  // the rig fills it without allocating
  double last_kept = -1e300;
  bool going = true;
  double prev_tick = 0;
  while (going) {
    next += period;
    sleep_until(next);
    const double now = mono_now();
    if (now - next > period) {  // counted, never hidden
      ++L.result.late_wakeups;
      if (ctx.live) ctx.live->late_wakeups.fetch_add(1, std::memory_order_relaxed);
      if (!blocks) {  // polling the latest value, a late period is a sample not taken in time
        ++L.result.missed_deadlines;
        if (ctx.live) ctx.live->missed_deadlines.fetch_add(1, std::memory_order_relaxed);
      }
    }
    if (ctx.loop_periods_us && prev_tick > 0) ctx.loop_periods_us->push_back(static_cast<float>((now - prev_tick) * 1e6));
    prev_tick = now;
    if (ctx.stop && ctx.stop->load()) {
      (void)ctx.rig.hold(true);
      L.result.state = "interrupted";
      L.result.reason = "the daemon is stopping";
      break;
    }
    const double t = (now - wall0) * ctx.time_scale;
    going = handle_control(L, t, wall0);
    if (!going) break;
    if (const auto ec = ctx.rig.read_samples(t, block)) {
      going = on_missed(L, ec);
      continue;
    }
    if (blocks) count_lost(L, lost_before);
    else L.answered_at = (mono_now() - wall0) * ctx.time_scale;  // a polled sample is stamped when asked
    bool fresh = false;
    for (const drivers::RigSample& s : block) {
      if (L.have_counter && s.sample_counter == L.last_counter) continue;
      L.have_counter = true;
      L.last_counter = s.sample_counter;
      fresh = true;
      // A controller faster than the plan: keep the plan's rate (its clock, not ours).
      if (blocks && s.time_s - last_kept < period * ctx.time_scale * (1 - 1e-6)) continue;
      last_kept = s.time_s;
      if (L.watchdog_holding) {  // the link is back: recover
        L.watchdog_holding = false;
        (void)ctx.rig.hold(false);
        L.seq.restart_at(L.seq.index());
      }
      going = on_sample(L, s, wall0) && !L.seq.done();
      if (!going) break;
    }
    if (!fresh) {
      going = on_missed(L, drivers::RigError::stale_data);
      continue;
    }
    L.watchdog.fresh();
    if (going == false && L.result.state.empty()) L.result.state = "completed";
  }
  if (blocks) count_lost(L, lost_before);
  L.result.dropped = ctx.writer.stats().dropped_full - dropped_before;
  finish_run(L.result, campaign_id, plan, L.builder.get(), L.fot.get(), L.series, ctx);
  L.state(L.result.state, L.result.reason.empty() ? "finished" : L.result.reason);
  return L.result;
}

}  // namespace hystlab::daemon
