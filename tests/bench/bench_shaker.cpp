// The sweep on the simulated shaker in real time: 5-100 Hz, up and down, at two base
// amplitudes, through the campaign runner as hystlabd runs it (the acquisition thread's priority
// and CPU, the simulator beside it, the writer ingesting). Prints the acquisition loop's missed
// deadlines and late wake-ups next to a bare 1 kHz sleep loop's in the same run (what the
// machine's scheduler alone allows), the worst step's control error, and the sweep's wall time
// against the plan's nominal time; then the resonance table and the jumps. Read in blocks from
// the controller's sample window (--polled: one sample asked for at a time). Then the resonance
// figure: the simulated isolator's peak refined from 12 steps until resolved, timed against a
// uniform sweep of the same resolution, on the fake clock in process (--no-resonance skips it).
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/daemon/realtime.hpp"
#include "hystlab/daemon/supervisor.hpp"
#include "hystlab/domain/envelope.hpp"
#include "hystlab/drivers/rig_factory.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/models/sweep_analysis.hpp"
#include "in_process_rig.hpp"
#include "realtime_bench.hpp"

using namespace hystlab;

namespace {
long bare_loop_missed(double seconds) {
  long missed = 0;
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  for (long k = 0; k < static_cast<long>(seconds * 1000); ++k) {
    next.tv_nsec += 1'000'000;
    if (next.tv_nsec >= 1'000'000'000) next.tv_nsec -= 1'000'000'000, ++next.tv_sec;
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    if ((now.tv_sec - next.tv_sec) * 1'000'000'000L + (now.tv_nsec - next.tv_nsec) > 1'000'000) ++missed;
  }
  return missed;
}

int report_points(db::Store& store, std::int64_t id, const domain::SinePlan& sine, bool completed) {
  std::vector<models::SweepCurvePoint> pts;
  double worst = 0;
  int beyond = 0;
  for (const db::TransmissibilityInfo& t : store.transmissibility(id)) {
    const auto d = nlohmann::json::parse(t.detail);
    const double e = std::fabs(d.value("control_error_pct", 0.0));
    worst = std::max(worst, e);
    beyond += e > sine.control.tolerance_pct ? 1 : 0;
    pts.push_back({t.demand_mm, t.direction == "up", {t.frequency_hz, t.ratio, t.phase_rad}});
  }
  const auto unreached = store.event_details(id, "control_unreached").size();
  std::printf(
      "points: %zu of %zu; worst step's control error %.2f %% (target <= 1 %%: %s; tolerance %.0f %%); %d points beyond the tolerance, %zu steps "
      "where control gave up after its windows\n",
      pts.size(), domain::step_count(sine), worst, worst <= 1.0 ? "met" : "NOT met", sine.control.tolerance_pct, beyond, unreached);
  const models::SweepReport r = models::analyse_sweep(pts, sine.jump_threshold_pct / 100);
  for (const models::SweepCurve& c : r.curves)
    if (c.resonance)
      std::printf("resonance %.3f mm %s: %.2f Hz, peak %.2f, half-power bandwidth %s%.2f Hz, Q %s%.1f%s\n", c.amplitude_mm, c.up ? "up" : "down",
                  c.resonance->frequency_hz, c.resonance->peak_ratio, c.resonance->resolved ? "" : "<= ", c.resonance->bandwidth_hz,
                  c.resonance->resolved ? "" : ">= ", c.resonance->q, c.resonance->resolved ? "" : " (steps coarser than the peak)");
  for (const models::AmplitudeJumps& a : r.jumps) {
    if (a.jumps.empty()) std::printf("%.3f mm: up and down agree within %.0f %%\n", a.amplitude_mm, sine.jump_threshold_pct);
    for (const models::Jump& j : a.jumps)
      std::printf("%.3f mm: up and down differ by up to %.0f %% between %.2f and %.2f Hz\n", a.amplitude_mm, 100 * j.max_difference, j.lo_hz, j.hi_hz);
  }
  // What can fail: a completed sweep has every point, and none beyond tolerance unless control said it gave up there.
  if (completed && pts.size() != domain::step_count(sine)) return 1;
  return completed && beyond > static_cast<int>(unreached) ? 1 : 0;
}

struct Swept {
  daemon::RunnerResult r;
  std::int64_t id = 0;
  double wall = 0;
};

Swept sweep(test::RealtimeBench& bench, const domain::Plan& plan, bool block_reads) {
  auto rig = drivers::make_rig({{"transport", "modbus-tcp"}, {"port", bench.sim.modbus_port}, {"rig", "shaker"}, {"block_reads", block_reads}});
  Swept s;
  s.id = bench.store.create_campaign(bench.store.upsert_rig("sim", "{}", "t"), domain::CampaignKind::sine, plan.source.dump(), "t");
  daemon::SteadyClock clock;
  daemon::Supervisor supervisor(*rig, domain::SupervisionSettings{}, true);
  daemon::RunnerContext ctx(*rig, supervisor, *bench.writer, clock);
  ctx.now_iso = [] { return std::string("t"); };
  daemon::CampaignJob job;
  job.id = s.id;
  job.plan = plan;
  job.plan.limits = domain::check_plan_against(plan, domain::RigEnvelope{}, domain::SupervisionSettings{}, true);
  const auto t0 = std::chrono::steady_clock::now();
  s.r = daemon::run_campaign(job, ctx);
  s.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  bench.writer->flush();
  return s;
}

// The same campaign on the fake clock against the simulator's shaker (its Table 1 springs) in
// process (drivers/sim/in_process_rig.hpp): what it measures and how long it takes in rig time
// are its own, not the machine's (issue 40: in real time this figure alone took 133 s of CI).
Swept sweep_in_process(test::RealtimeBench& bench, const domain::Plan& plan) {
  const models::SimplifiedSmaModel spring(models::table1_parameters());
  sim::InProcessRig rig(sim::SimRig(std::make_unique<sim::ShakerSim>(spring, sim::ShakerParams{})), 1000);
  Swept s;
  s.id = bench.store.create_campaign(bench.store.upsert_rig("sim", "{}", "t"), domain::CampaignKind::sine, plan.source.dump(), "t");
  daemon::FakeClock clock;
  daemon::Supervisor supervisor(rig, domain::SupervisionSettings{}, true);
  daemon::RunnerContext ctx(rig, supervisor, *bench.writer, clock);
  ctx.now_iso = [] { return std::string("t"); };
  daemon::CampaignJob job;
  job.id = s.id;
  job.plan = plan;
  job.plan.limits = domain::check_plan_against(plan, domain::RigEnvelope{}, domain::SupervisionSettings{}, true);
  const double t0 = clock.now();
  s.r = daemon::run_campaign(job, ctx);
  s.wall = clock.now() - t0;  // rig seconds
  bench.writer->flush();
  return s;
}

// The simulated isolator at 0.005 mm (its springs on their elastic line: Q about 25 at 17.7 Hz)
// from 12 log steps, refined until its half-power band holds 5 points; against a uniform log
// sweep of the same resolution (5 points in a band of f/Q at Q = 25), at its nominal time. On the
// fake clock: the refinement's rig time is deterministic.
int resonance_figure(test::RealtimeBench& bench) {
  const nlohmann::json base = {{"kind", "sine"},        {"sweep", {{"from_hz", 5}, {"to_hz", 100}, {"steps", 12}}},
                               {"amplitude_mm", 0.005}, {"settle", {{"change", "1 %"}, {"consecutive", 2}}},
                               {"measured_cycles", 10}, {"sample_rate_hz", 1000}};
  nlohmann::json refined = base;
  refined["resonance"] = {{"half_power_points", 5}};
  const auto plan = domain::parse_plan(refined);
  const Swept s = sweep_in_process(bench, plan);
  std::vector<models::SweepPoint> pts;
  for (const db::TransmissibilityInfo& t : bench.store.transmissibility(s.id)) pts.push_back({t.frequency_hz, t.ratio, t.phase_rad});
  const auto res = models::find_resonance(pts);
  nlohmann::json uniform = base;
  const int steps = static_cast<int>(std::ceil(std::log(100.0 / 5.0) / (std::log1p(1.0 / 25) / 5))) + 1;
  uniform["sweep"]["steps"] = steps;
  const double uniform_s = domain::nominal_duration_s(domain::parse_plan(uniform).sine);
  std::printf(
      "resonance refinement (fake clock, in process): campaign %s; %zu points (12 planned), resonance %.2f Hz, Q %.1f%s, %d points in its "
      "half-power band; %.1f s of rig time against a uniform sweep of the same resolution (%d log steps, nominal %.0f s): ratio %.3f\n",
      daemon::to_string(s.r.end), pts.size(), res ? res->frequency_hz : 0.0, res ? res->q : 0.0, res && res->resolved ? "" : " (NOT resolved)",
      res ? models::points_in_band(*res, pts) : 0, s.wall, steps, uniform_s, s.wall / uniform_s);
  return s.r.end == daemon::CampaignEnd::completed && res && models::band_holds(pts, 5) ? 0 : 1;
}
}  // namespace

int main(int argc, char** argv) {
  int steps = 12;
  bool polled = false, resonance = true;
  for (int k = 1; k < argc; ++k) {
    if (!std::strcmp(argv[k], "--steps") && k + 1 < argc) steps = std::atoi(argv[++k]);
    if (!std::strcmp(argv[k], "--polled")) polled = true;  // the controller's sample window not used: each sample asked for
    if (!std::strcmp(argv[k], "--no-resonance")) resonance = false;
  }
  test::RealtimeBench bench({"--rig", "shaker", "--port", "0"});
  const auto plan = domain::parse_plan({{"kind", "sine"},
                                        {"sweep", {{"from_hz", 5}, {"to_hz", 100}, {"steps", steps}}},
                                        {"direction", "up-down"},
                                        {"amplitudes_mm", {0.005, 0.05}},
                                        {"settle_cycles", 10},
                                        {"measured_cycles", 10},
                                        {"sample_rate_hz", 1000}});
  const double nominal = domain::nominal_duration_s(plan.sine);
  const Swept s = sweep(bench, plan, !polled);
  const daemon::RunnerResult& r = s.r;
  const double wall = s.wall;
  // The baseline: a bare 1 kHz loop for a quarter of the sweep's time (its rate of missed periods is what compares).
  const double base_s = std::max(10.0, wall / 4);
  const long base_missed = bare_loop_missed(base_s);
  std::printf("sweep 5-100 Hz up-down at 0.005 and 0.05 mm, %d steps a pass, %s: campaign %s%s%s\n", steps,
              polled ? "polled" : "block reads of the controller's sample window", daemon::to_string(r.end), r.reason.empty() ? "" : ": ", r.reason.c_str());
  std::printf(
      "acquisition loop: %llu samples, missed deadlines %llu (%.2f a minute), late wake-ups %llu, gaps %llu (longest %.0f ms); "
      "bare 1 kHz loop: %ld missed in %.0f s (%.2f a minute) (target: 0 missed: %s)\n",
      static_cast<unsigned long long>(r.samples), static_cast<unsigned long long>(r.missed_deadlines), 60.0 * static_cast<double>(r.missed_deadlines) / wall,
      static_cast<unsigned long long>(r.late_wakeups), static_cast<unsigned long long>(r.gaps), r.longest_gap_s * 1e3, base_missed, base_s,
      60.0 * static_cast<double>(base_missed) / base_s, r.missed_deadlines == 0 ? "met" : "NOT met");
  std::printf("wall time %.1f s against the plan's nominal %.1f s: ratio %.2f\n", wall, nominal, wall / nominal);
  int rc = report_points(bench.store, s.id, plan.sine, r.end == daemon::CampaignEnd::completed);
  if (resonance) rc |= resonance_figure(bench);
  return rc;
}
