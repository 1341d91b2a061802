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

#include "../drivers/sim_process.hpp"
#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/daemon/realtime.hpp"
#include "hystlab/drivers/rig_factory.hpp"

using namespace hystlab;

namespace {
void report(const char* what, std::vector<float> p, long missed) {
  std::sort(p.begin(), p.end(), [](float a, float b) { return std::fabs(a - 1000) < std::fabs(b - 1000); });
  std::vector<double> jitter;
  for (float v : p) jitter.push_back(std::fabs(v - 1000.0));
  std::sort(jitter.begin(), jitter.end());
  const auto q = [&](double f) { return jitter[static_cast<std::size_t>(f * static_cast<double>(jitter.size() - 1))]; };
  std::printf("%s: %zu periods; |period - 1 ms| p50 %.1f us, p99 %.1f us, p99.9 %.1f us, max %.1f us; "
              "missed deadlines (a whole period late) %ld\n", what, jitter.size(), q(0.5), q(0.99), q(0.999), jitter.back(), missed);
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
    const auto ns = [](const timespec& a, const timespec& b) {
      return static_cast<double>((a.tv_sec - b.tv_sec) * 1'000'000'000L + (a.tv_nsec - b.tv_nsec));
    };
    if (ns(now, next) > 1e6) ++missed;
    if (k) out.push_back(static_cast<float>(ns(now, prev) / 1e3));
    prev = now;
  }
  return out;
}
}  // namespace

int main(int argc, char** argv) {
  double seconds = 60;
  for (int k = 1; k + 1 < argc; k += 2)
    if (!std::strcmp(argv[k], "--seconds")) seconds = std::atof(argv[k + 1]);
  const daemon::AcquisitionSettings settings;  // the daemon's defaults
  test::SimProcess sim({"--port", "0", "--noise", "0.05", "--realtime", std::to_string(settings.priority - 1)});
  if (!daemon::pin_process(sim.pid(), daemon::resolve_cpu(settings.cpu))) std::printf("the simulator is not pinned\n");
  char tmpl[] = "/tmp/hystlab-acq-XXXXXX";
  const std::filesystem::path dir = mkdtemp(tmpl);
  const std::string path = (dir / "hystlab.db").string();
  db::Store store(path);
  // As in hystlabd: the writer's thread starts at normal priority, off the acquisition's CPU.
  const bool moved = daemon::avoid_cpu(daemon::resolve_cpu(settings.cpu));
  db::SampleWriter writer(path);
  if (moved) (void)daemon::avoid_cpu(-1);
  std::printf("this thread: %s\n", daemon::enter_acquisition_thread(settings).c_str());
  long base_missed = 0;
  report("baseline: bare 1 kHz sleep loop", sleep_loop(seconds / 3, base_missed), base_missed);

  auto rig = drivers::make_rig({{"transport", "modbus-tcp"}, {"port", sim.modbus_port}});
  nlohmann::json points = nlohmann::json::array();
  const int legs = std::max(2, static_cast<int>(seconds / 1.5));
  for (int k = 0; k <= legs; ++k) points.push_back(k % 2 ? 3.0 : 0.0);  // 1.5 s legs at 2 mm/s
  const auto plan = daemon::parse_plan({{"kind", "waveform"}, {"points_mm", points}, {"ramp_rate_mm_s", 2.0}, {"sample_rate_hz", 1000},
                                        {"limits", {{"displacement_mm", {-1, 4}}, {"force_N", 400}, {"rate_mm_s", 50}}}});
  const auto id = store.create_campaign(store.upsert_rig("sim", "{}", "t"), "waveform", plan.source.dump(), "t");
  std::vector<float> periods;
  periods.reserve(static_cast<std::size_t>(seconds * 1100));
  daemon::RunnerContext ctx(*rig, writer, store);
  ctx.now_iso = [] { return std::string("t"); };
  ctx.loop_periods_us = &periods;
  const auto r = daemon::run_campaign(id, plan, ctx);
  writer.flush();
  const db::WriterStats w = writer.stats();
  report("acquisition (ModbusRig -> hystlab-sim, runner, writer ingesting)", periods, static_cast<long>(r.missed_deadlines));
  std::printf("campaign %s%s%s; %llu samples, %llu written, %llu dropped (ring full), %llu commits, max commit %.1f ms "
              "(target: p99.9 within 1 ms, no missed deadlines beyond the baseline's)\n",
              r.state.c_str(), r.reason.empty() ? "" : ": ", r.reason.c_str(), static_cast<unsigned long long>(r.samples), static_cast<unsigned long long>(w.written),
              static_cast<unsigned long long>(w.dropped_full), static_cast<unsigned long long>(w.commits), w.max_commit_ms);
  std::filesystem::remove_all(dir);
  return r.state == "completed" ? 0 : 1;
}
