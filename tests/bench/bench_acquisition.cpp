// A 1 kHz acquisition for 60 s through the campaign runner (rig reads, safety, sequencer, ring
// push) while the writer thread ingests; next to a bare 1 kHz sleep loop in the same run, which
// is what the machine's scheduler alone allows. Both run as hystlabd runs a rig's acquisition
// thread (daemon/realtime.hpp: SCHED_FIFO 20 when allowed, pinned to the last CPU), with the
// simulator where hystlabd puts it (that CPU, SCHED_FIFO 19) and the writer at normal priority
// on the other CPUs.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <vector>

#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/daemon/realtime.hpp"
#include "hystlab/daemon/supervisor.hpp"
#include "hystlab/db/sqlite.hpp"
#include "hystlab/domain/envelope.hpp"
#include "hystlab/drivers/rig_factory.hpp"
#include "realtime_bench.hpp"

using namespace hystlab;

namespace {
void report(const char* what, std::vector<float> p, long missed) {
  std::sort(p.begin(), p.end(), [](float a, float b) { return std::fabs(a - 1000) < std::fabs(b - 1000); });
  std::vector<double> jitter;
  for (float v : p) jitter.push_back(std::fabs(v - 1000.0));
  std::sort(jitter.begin(), jitter.end());
  const auto q = [&](double f) { return jitter[static_cast<std::size_t>(f * static_cast<double>(jitter.size() - 1))]; };
  std::printf(
      "%s: %zu periods; |period - 1 ms| p50 %.1f us, p99 %.1f us, p99.9 %.1f us, max %.1f us; "
      "missed deadlines (a whole period late) %ld\n",
      what, jitter.size(), q(0.5), q(0.99), q(0.999), jitter.back(), missed);
}

std::vector<float> sleep_loop(double seconds, long& missed) {
  std::vector<float> out;
  timespec next{}, prev{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  prev = next;
  for (long k = 0; k < static_cast<long>(seconds * 1000); ++k) {
    next.tv_nsec += 1'000'000;
    if (next.tv_nsec >= 1'000'000'000) next.tv_nsec -= 1'000'000'000, ++next.tv_sec;
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);
    const auto ns = [](const timespec& a, const timespec& b) { return static_cast<double>((a.tv_sec - b.tv_sec) * 1'000'000'000L + (a.tv_nsec - b.tv_nsec)); };
    if (ns(now, next) > 1e6) ++missed;
    if (k) out.push_back(static_cast<float>(ns(now, prev) / 1e3));
    prev = now;
  }
  return out;
}
// One waveform campaign through the runner at 1 kHz for `seconds`; prints the loop's periods
// (the host's wake-ups) and the stored samples' spacing (the time axis the data keeps).
daemon::RunnerResult acquire(bool blocks, int port, double seconds, db::Store& store, db::SampleWriter& writer, const std::string& path) {
  auto rig = drivers::make_rig({{"transport", "modbus-tcp"}, {"port", port}, {"block_reads", blocks}});
  nlohmann::json points = nlohmann::json::array();
  const int legs = std::max(2, static_cast<int>(seconds / 1.5));
  for (int k = 0; k <= legs; ++k) points.push_back(k % 2 ? 3.0 : 0.0);  // 1.5 s legs at 2 mm/s
  const auto plan = domain::parse_plan({{"kind", "waveform"},
                                        {"points_mm", points},
                                        {"ramp_rate_mm_s", 2.0},
                                        {"sample_rate_hz", 1000},
                                        {"limits", {{"displacement_mm", {-1, 4}}, {"force_N", 400}, {"rate_mm_s", 50}}}});
  const auto id = store.create_campaign(store.upsert_rig("sim", "{}", "t"), hystlab::domain::CampaignKind::waveform, plan.source.dump(), "t");
  std::vector<float> periods;
  periods.reserve(static_cast<std::size_t>(seconds * 1100));
  daemon::SteadyClock clock;
  daemon::Supervisor supervisor(*rig, domain::SupervisionSettings{}, false);
  daemon::RunnerContext ctx(*rig, supervisor, writer, clock);
  ctx.now_iso = [] { return std::string("t"); };
  ctx.loop_periods_us = &periods;
  daemon::CampaignJob job;
  job.id = id;
  job.plan = plan;
  job.plan.limits = domain::check_plan_against(plan, domain::RigEnvelope{}, domain::SupervisionSettings{}, false);
  const auto r = daemon::run_campaign(job, ctx);
  writer.flush();
  const db::WriterStats w = writer.stats();
  const std::string what = blocks ? "block reads" : "polling";
  report((what + ": loop (ModbusRig -> hystlab-sim, runner, writer ingesting)").c_str(), periods, static_cast<long>(r.late_wakeups));
  db::Database d(path);
  db::Statement q(d,
                  "SELECT COUNT(*), MAX(dt), SUM(dt > 0.0015), SUM(ABS(dt - 0.001) > 1e-6) FROM "
                  "(SELECT t - LAG(t) OVER (ORDER BY seq) AS dt FROM samples WHERE run_id = ?) WHERE dt IS NOT NULL");
  q.bind(1, r.run_id);
  q.step();
  std::printf("%s: stored samples' spacing: %lld intervals, max %.3f ms, %lld over 1.5 ms, %lld off 1 ms by more than 1 us\n", what.c_str(),
              static_cast<long long>(q.column_double(0)), q.column_double(1) * 1e3, static_cast<long long>(q.column_double(2)),
              static_cast<long long>(q.column_double(3)));
  std::printf(
      "%s: campaign %s%s%s; %llu samples, %llu written in all, %llu dropped (ring full), %llu commits, max commit %.1f ms; "
      "rig: %llu samples lost\n",
      what.c_str(), daemon::to_string(r.end), r.reason.empty() ? "" : ": ", r.reason.c_str(), static_cast<unsigned long long>(r.samples),
      static_cast<unsigned long long>(w.written), static_cast<unsigned long long>(w.dropped_full), static_cast<unsigned long long>(w.commits), w.max_commit_ms,
      static_cast<unsigned long long>(rig->health().lost_samples));
  return r;
}
}  // namespace

int main(int argc, char** argv) {
  double seconds = 60;
  for (int k = 1; k + 1 < argc; k += 2)
    if (!std::strcmp(argv[k], "--seconds")) seconds = std::atof(argv[k + 1]);
  test::RealtimeBench bench({"--port", "0", "--noise", "0.05"});
  db::Store& store = bench.store;
  db::SampleWriter& writer = *bench.writer;
  const std::string& path = bench.path;
  // The baseline runs as long as the acquisition, half before it and half after, so that both
  // see the same share of the machine's noise and their missed deadlines compare one to one.
  long base_missed = 0;
  std::vector<float> base = sleep_loop(seconds / 2, base_missed);

  const auto polled = acquire(false, bench.sim.modbus_port, seconds, store, writer, path);
  std::vector<float> after = sleep_loop(seconds / 2, base_missed);
  base.insert(base.end(), after.begin(), after.end());
  const auto blocks = acquire(true, bench.sim.modbus_port, seconds, store, writer, path);
  report("baseline: bare 1 kHz sleep loop (half before polling, half between)", std::move(base), base_missed);
  std::printf("polling: missed deadlines (late periods) %ld, bare loop %ld over the same time: %+ld beyond the baseline\n",
              static_cast<long>(polled.missed_deadlines), base_missed, static_cast<long>(polled.missed_deadlines) - base_missed);
  std::printf(
      "block reads (as hystlabd reads a controller in real time): missed deadlines (samples lost) %ld, "
      "late wake-ups %ld (target: p99.9 within 1 ms, no missed deadlines)\n",
      static_cast<long>(blocks.missed_deadlines), static_cast<long>(blocks.late_wakeups));
  return polled.end == daemon::CampaignEnd::completed && blocks.end == daemon::CampaignEnd::completed ? 0 : 1;
}
