// A campaign's run from start to end (run_campaign): the run's rows created, the arming
// handshake, the periods (acquisition_tick.cpp), then the rig left and the finished run handed off.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <system_error>
#include <utility>

#include "acquisition_tick.hpp"

namespace hystlab::daemon {

namespace {
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
