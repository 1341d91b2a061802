// The sweep on the simulated shaker in real time: 5-100 Hz, up and down, at two base
// amplitudes, through the campaign runner as hystlabd runs it (the acquisition thread's priority
// and CPU, the simulator beside it, the writer ingesting). Prints the acquisition loop's missed
// deadlines and late wake-ups next to a bare 1 kHz sleep loop's in the same run (what the
// machine's scheduler alone allows), the worst step's control error, and the sweep's wall time
// against the plan's nominal time; then the resonance table and the jumps.
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
#include "hystlab/models/sweep_analysis.hpp"
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
      "points: %zu of %zu; worst step's control error %.2f %% (tolerance %.0f %%); %d points beyond it, %zu steps where control "
      "gave up after its windows\n",
      pts.size(), domain::step_count(sine), worst, sine.control.tolerance_pct, beyond, unreached);
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
}  // namespace

int main(int argc, char** argv) {
  int steps = 12;
  for (int k = 1; k + 1 < argc; k += 2)
    if (!std::strcmp(argv[k], "--steps")) steps = std::atoi(argv[k + 1]);
  test::RealtimeBench bench({"--rig", "shaker", "--port", "0"});
  db::Store& store = bench.store;
  db::SampleWriter& writer = *bench.writer;

  const auto plan = domain::parse_plan({{"kind", "sine"},
                                        {"sweep", {{"from_hz", 5}, {"to_hz", 100}, {"steps", steps}}},
                                        {"direction", "up-down"},
                                        {"amplitudes_mm", {0.005, 0.05}},
                                        {"settle_cycles", 10},
                                        {"measured_cycles", 10},
                                        {"sample_rate_hz", 1000}});
  auto rig = drivers::make_rig({{"transport", "modbus-tcp"}, {"port", bench.sim.modbus_port}, {"rig", "shaker"}});
  const auto id = store.create_campaign(store.upsert_rig("sim", "{}", "t"), domain::CampaignKind::sine, plan.source.dump(), "t");
  daemon::SteadyClock clock;
  daemon::Supervisor supervisor(*rig, domain::SupervisionSettings{}, true);
  daemon::RunnerContext ctx(*rig, supervisor, writer, clock);
  ctx.now_iso = [] { return std::string("t"); };
  daemon::CampaignJob job;
  job.id = id;
  job.plan = plan;
  job.plan.limits = domain::check_plan_against(plan, domain::RigEnvelope{}, domain::SupervisionSettings{}, true);
  const double nominal = domain::nominal_duration_s(plan.sine);
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = daemon::run_campaign(job, ctx);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  writer.flush();
  // The baseline: a bare 1 kHz loop for a quarter of the sweep's time (its rate of missed periods is what compares).
  const double base_s = std::max(10.0, wall / 4);
  const long base_missed = bare_loop_missed(base_s);
  std::printf("sweep 5-100 Hz up-down at 0.005 and 0.05 mm, %d steps a pass: campaign %s%s%s\n", steps, daemon::to_string(r.end), r.reason.empty() ? "" : ": ",
              r.reason.c_str());
  std::printf(
      "acquisition loop: %llu samples, missed deadlines %llu (%.2f a minute), late wake-ups %llu, gaps %llu (longest %.0f ms); "
      "bare 1 kHz loop: %ld missed in %.0f s (%.2f a minute) (target: 0 missed)\n",
      static_cast<unsigned long long>(r.samples), static_cast<unsigned long long>(r.missed_deadlines), 60.0 * static_cast<double>(r.missed_deadlines) / wall,
      static_cast<unsigned long long>(r.late_wakeups), static_cast<unsigned long long>(r.gaps), r.longest_gap_s * 1e3, base_missed, base_s,
      60.0 * static_cast<double>(base_missed) / base_s);
  std::printf("wall time %.1f s against the plan's nominal %.1f s: ratio %.2f\n", wall, nominal, wall / nominal);
  return report_points(store, id, plan.sine, r.end == daemon::CampaignEnd::completed);
}
