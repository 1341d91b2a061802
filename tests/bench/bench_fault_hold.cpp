// The time from a fault bit appearing on the rig to the hold command being sent, over 1,000
// injected faults at 1 kHz: the real acquisition loop, supervisor, writer and SQLite file on the
// real clock, with the in-process controller of the unit tests (tests/daemon/fake_rig.hpp), so
// what is measured is the host's path and not a network's. A fault latches at a random moment of
// a moving ramp; "appeared" is that moment on the rig's own time line (the loop's rig time), and
// "sent" is the wall time at which hold(true) reached the rig. Printed as p50/p99/max in µs and
// as a ratio to the sample period measured in the same run (the baseline); the target is
// <= 2 sample periods at p99. Asserts only that every fault was held and the campaign failed.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "../daemon/fake_rig.hpp"
#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/daemon/clock.hpp"
#include "hystlab/daemon/supervisor.hpp"
#include "hystlab/domain/envelope.hpp"

using namespace hystlab;
namespace fs = std::filesystem;

namespace {
double wall() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// The fake controller, with the wall time of every read (to place the fault on the wall clock)
// and of the first hold(true) after the fault.
class TimedRig final : public drivers::Rig {
 public:
  explicit TimedRig(double fault_at_rig_s) : fault_at_(fault_at_rig_s) { rig_.plan.push_back({test::FaultEvent::latch_fault, fault_at_rig_s, 1e9, 7}); }
  std::error_code connect(double t) noexcept override { return rig_.connect(t); }
  void disconnect() noexcept override { rig_.disconnect(); }
  std::error_code arm(bool on) noexcept override { return rig_.arm(on); }
  std::error_code command(double sp, double rate) noexcept override { return rig_.command(sp, rate); }
  std::error_code hold(bool on) noexcept override {
    if (on && appeared_wall_ > 0 && hold_wall_ == 0) hold_wall_ = wall();
    return rig_.hold(on);
  }
  std::error_code estop(bool on) noexcept override { return rig_.estop(on); }
  std::error_code set_mode(std::uint16_t m) noexcept override { return rig_.set_mode(m); }
  std::error_code reset_faults() noexcept override { return rig_.reset_faults(); }
  std::string fault_text(std::uint16_t c) const override { return rig_.fault_text(c); }
  std::error_code read_sample(double now, drivers::RigSample& out) noexcept override {
    const double w = wall();
    const auto ec = rig_.read_sample(now, out);
    // The first read at or after the fault: it appeared (now - fault_at) of rig time ago.
    if (appeared_wall_ == 0 && now >= fault_at_) appeared_wall_ = w - (now - fault_at_);
    return ec;
  }
  [[nodiscard]] drivers::IoHealthSnapshot health() const noexcept override { return {}; }
  [[nodiscard]] std::string describe() const override { return "timed fake rig"; }
  [[nodiscard]] double latency_s() const { return hold_wall_ > 0 ? hold_wall_ - appeared_wall_ : -1; }

 private:
  test::FakeRig rig_;
  double fault_at_;
  double appeared_wall_ = 0, hold_wall_ = 0;
};

double pct(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}
}  // namespace

int main(int argc, char** argv) {
  int faults = 1000;
  for (int i = 1; i + 1 < argc; ++i)
    if (std::strcmp(argv[i], "--faults") == 0) faults = std::atoi(argv[i + 1]);
  char tmpl[] = "/tmp/hystlab-bench-fault-XXXXXX";
  const fs::path dir = mkdtemp(tmpl);
  const std::string path = (dir / "bench.db").string();
  int failures = 0;
  std::vector<double> latency, periods;
  {
    db::Store store(path);
    db::SampleWriter writer(path, db::WriterOptions{1U << 16, 0.1, 50'000, false});
    const auto rig_id = store.upsert_rig("fake", "{}", "t");
    const nlohmann::json plan_json{{"kind", "waveform"}, {"points_mm", {0.0, 3.0}}, {"ramp_rate_mm_s", 2.0}, {"sample_rate_hz", 1000}};
    daemon::SteadyClock clock;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> at(0.010, 0.030);  // after arming, while the ramp moves
    std::vector<float> loop_periods;
    loop_periods.reserve(static_cast<std::size_t>(faults) * 64);
    for (int k = 0; k < faults; ++k) {
      TimedRig rig(at(rng));
      daemon::Supervisor sup(rig, domain::SupervisionSettings{}, false);
      daemon::CampaignJob job;
      job.plan = domain::parse_plan(plan_json);
      job.plan.limits = domain::check_plan_against(job.plan, domain::RigEnvelope{}, domain::SupervisionSettings{}, false);
      job.id = store.create_campaign(rig_id, hystlab::domain::CampaignKind::waveform, plan_json.dump(), "t");
      daemon::RunnerContext ctx(rig, sup, writer, clock);
      ctx.now_iso = [] { return std::string("t"); };
      ctx.loop_periods_us = &loop_periods;
      const auto r = daemon::run_campaign(job, ctx);
      const bool ok = r.end == daemon::CampaignEnd::failed && r.reason.find("fault 7") != std::string::npos && rig.latency_s() >= 0;
      if (!ok) {
        if (++failures <= 3) std::printf("fault %d not held as expected: %s (%s)\n", k, daemon::to_string(r.end), r.reason.c_str());
        continue;
      }
      latency.push_back(rig.latency_s() * 1e6);
    }
    writer.flush();
    for (float p : loop_periods) periods.push_back(p);
  }
  fs::remove_all(dir);
  if (latency.empty() || periods.empty()) {
    std::printf("FAILED: no fault was held\n");
    return 1;
  }
  const double period_us = pct(periods, 0.5);  // the baseline: the loop's own sample period, this run
  std::printf("fault -> hold over %zu faults at 1 kHz (sample period p50 %.0f us, this run):\n", latency.size(), period_us);
  for (const auto& [name, p] : {std::pair{"p50", 0.5}, std::pair{"p99", 0.99}, std::pair{"max", 1.0}}) {
    const double v = p < 1.0 ? pct(latency, p) : *std::max_element(latency.begin(), latency.end());
    std::printf("  %s %8.0f us = %5.2f sample periods\n", name, v, v / period_us);
  }
  std::printf("  target: p99 <= 2 sample periods: %s\n", pct(latency, 0.99) <= 2 * period_us ? "met" : "NOT met");
  if (failures > 0) {
    std::printf("FAILED: %d of %d faults did not end their campaign held\n", failures, faults);
    return 1;
  }
  return 0;
}
