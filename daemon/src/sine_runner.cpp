// Sine campaigns on a shaker: each frequency is driven for settle_cycles, then measured for
// measured_cycles; amplitude and phase of base and mass motion come from a least-squares sine fit,
// and the transmissibility point is stored as it comes.
#include <chrono>
#include <cmath>
#include <numbers>
#include <nlohmann/json.hpp>
#include <vector>

#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/daemon/safety.hpp"
#include "hystlab/models/sine_fit.hpp"
#include "monotonic_clock.hpp"

namespace hystlab::daemon {
namespace {
struct Step {
  std::vector<double> t, base, mass;
};
}  // namespace

RunnerResult run_sine_campaign(std::int64_t campaign_id, const Plan& plan, RunnerContext& ctx) {
  RunnerResult r;
  auto state = [&](const std::string& to, const std::string& reason) {
    const std::string now = ctx.now_iso();
    ctx.writer.post([campaign_id, to, reason, now](db::Store& s) { s.transition(campaign_id, to, reason, now); });
    if (ctx.on_state) ctx.on_state(to);
  };
  state("arming", "started by the daemon");
  const double wall0 = mono_now();
  drivers::ShakerSample s;
  (void)ctx.rig.connect(0.0);
  if (auto ec = ctx.rig.read_shaker(0.0, s)) {
    r.state = "failed";
    r.reason = ec == drivers::RigError::unsupported ? "a sine campaign needs a shaker; this rig is not one" : "cannot read the shaker: " + ec.message();
    state(r.state, r.reason);
    return r;
  }
  r.run_id = ctx.store.add_run(campaign_id, ctx.now_iso(), 0.0, wall0);
  state("running", "armed");
  Watchdog watchdog(ctx.watchdog_hold_periods, ctx.watchdog_fail_periods);
  const double period = 1.0 / plan.sample_rate_hz;
  double next = mono_now();
  std::int64_t seq = 0;
  std::uint32_t last_counter = 0;
  for (std::size_t k = 0; k < plan.frequencies_hz.size() && r.state.empty(); ++k) {
    const double f = plan.frequencies_hz[k];
    if (auto ec = ctx.rig.command_shaker(f, plan.amplitude_mm, true)) {
      r.state = "failed";
      r.reason = "shaker command refused: " + ec.message();
      break;
    }
    const double t_start = (mono_now() - wall0) * ctx.time_scale;
    const double t_measure = t_start + plan.settle_cycles / f, t_end = t_measure + plan.measured_cycles / f;
    Step step;
    for (double t = t_start; t < t_end && r.state.empty();) {
      next += period;
      sleep_until(next);
      if (mono_now() - next > period) {
        ++r.missed_deadlines;  // polling: a late wake-up is a sample not taken in time
        ++r.late_wakeups;
        if (ctx.live) {
          ctx.live->missed_deadlines.fetch_add(1, std::memory_order_relaxed);
          ctx.live->late_wakeups.fetch_add(1, std::memory_order_relaxed);
        }
      }
      t = (mono_now() - wall0) * ctx.time_scale;
      if (ctx.stop && ctx.stop->load()) r.state = "interrupted", r.reason = "the daemon is stopping";
      if (const auto c = ctx.next_control(); c && (*c == Control::abort || *c == Control::estop)) {
        if (*c == Control::estop) (void)ctx.rig.estop(true);
        r.state = "aborted";
        r.reason = *c == Control::estop ? "e-stop by the operator" : "aborted by the operator";
      }
      if (!r.state.empty()) break;
      if (auto ec = ctx.rig.read_shaker(t, s); ec || s.sample_counter == last_counter) {
        if (watchdog.missed() == Watchdog::Verdict::fail)
          r.state = "failed", r.reason = "watchdog: no fresh shaker sample (" + (ec ? ec.message() : std::string("stale")) + ")";
        continue;
      }
      watchdog.fresh();
      last_counter = s.sample_counter;
      // Shaker samples: base displacement in cmd, mass displacement in disp, mass acceleration in force.
      ctx.writer.try_push({r.run_id, seq++, t, s.base_displacement_mm, s.mass_displacement_mm, s.mass_accel_m_s2, s.status_word});
      ++r.samples;
      if (ctx.live) {
        ctx.live->ring.push({mono_now(), t, s.base_displacement_mm, s.mass_displacement_mm, s.mass_accel_m_s2, r.run_id, s.status_word});
        ctx.live->samples.fetch_add(1, std::memory_order_relaxed);
      }
      if (std::fabs(s.mass_displacement_mm) > plan.limits.displacement_max_mm)
        r.state = "aborted", r.reason = "safety trip: mass displacement beyond the limits";
      if (t >= t_measure) {
        step.t.push_back(t);
        step.base.push_back(s.base_displacement_mm);
        step.mass.push_back(s.mass_displacement_mm);
      }
    }
    if (!r.state.empty()) break;
    const models::SineFit b = models::fit_sine(step.t, step.base, f), m = models::fit_sine(step.t, step.mass, f);
    if (!b.ok || !m.ok || b.amplitude <= 0) {
      r.state = "failed";
      r.reason = "too few samples to fit the sine at " + std::to_string(f) + " Hz";
      break;
    }
    const double ratio = m.amplitude / b.amplitude, phase = std::remainder(m.phase_rad - b.phase_rad, 2 * std::numbers::pi);
    const auto run = r.run_id;
    const std::string now = ctx.now_iso();
    ctx.writer.post([run, f, b, m, ratio, phase, campaign_id, now](db::Store& st) {
      st.add_transmissibility(run, f, b.amplitude, m.amplitude, ratio, phase);
      st.add_event(campaign_id, "transmissibility",
                   nlohmann::json{{"frequency_hz", f}, {"ratio", ratio}, {"phase_rad", phase}}.dump(), now);
    });
  }
  (void)ctx.rig.command_shaker(0.0, 0.0, false);
  if (r.state.empty()) r.state = "completed";
  ctx.writer.flush();
  ctx.store.end_run(r.run_id, r.state, ctx.now_iso());
  state(r.state, r.reason.empty() ? "finished" : r.reason);
  return r;
}

}  // namespace hystlab::daemon
