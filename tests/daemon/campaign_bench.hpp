#pragma once
// The campaign tests' bench (test_campaign.cpp, test_shaker_campaign.cpp): a database file with
// its writer, operator controls, a rig over Modbus TCP, and a runner context, as the daemon
// builds them.
#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>

#include "../support/temp_dir.hpp"
#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/daemon/supervisor.hpp"
#include "hystlab/domain/envelope.hpp"
#include "hystlab/drivers/rig_factory.hpp"

namespace hystlab::test {
namespace fs = std::filesystem;
namespace {  // each test program's own copy

struct Bench {  // a db file, a writer, and a campaign row
  Bench(std::size_t capacity = 1U << 17) {
    path = (dir / "hystlab.db").string();
    store = std::make_unique<db::Store>(path);
    writer = std::make_unique<db::SampleWriter>(path, db::WriterOptions{capacity, 0.1, 50'000, true});
    rig_id = store->upsert_rig("sim", "{}", "t");
  }
  ~Bench() {
    writer.reset();
    store.reset();
  }
  std::int64_t submit(const nlohmann::json& plan) { return store->create_campaign(rig_id, domain::parse_plan(plan).kind, plan.dump(), "t"); }
  test_support::TempDir tmp{"campaign"};
  fs::path dir = tmp.path();
  std::string path;
  std::unique_ptr<db::Store> store;
  std::unique_ptr<db::SampleWriter> writer;
  std::int64_t rig_id = 0;
  daemon::SteadyClock clock;
  std::unique_ptr<daemon::Supervisor> sup;  // one per rig, as in the daemon
};

struct Controls {  // what the HTTP threads will do: queue commands for the acquisition thread
  std::mutex mu;
  std::deque<daemon::Control> q;
  void push(daemon::Control c) {
    std::lock_guard lk(mu);
    q.push_back(c);
  }
  std::optional<daemon::Control> pop() {
    std::lock_guard lk(mu);
    if (q.empty()) return std::nullopt;
    auto c = q.front();
    q.pop_front();
    return c;
  }
};

[[maybe_unused]] nlohmann::json fot_plan(int n, double rate = 0.1) {
  return {{"kind", "fot"},          {"range_mm", {0.0, 4.0}}, {"subdivisions", n},
          {"ramp_rate_mm_s", rate}, {"sample_rate_hz", 1000}, {"limits", {{"displacement_mm", {-0.5, 4.5}}, {"force_N", 400}, {"rate_mm_s", 50}}}};
}

[[maybe_unused]] std::unique_ptr<drivers::Rig> tcp_rig(int port) {
  return drivers::make_rig(
      {{"transport", "modbus-tcp"}, {"port", port}, {"response_timeout_ms", 50}, {"reconnect_min_ms", 10}, {"reconnect_max_ms", 20}, {"stale_after_ms", 5000}});
}

[[maybe_unused]] daemon::RunnerContext context(drivers::Rig& rig, Bench& b, Controls* c, double scale, bool shaker = false) {
  b.sup = std::make_unique<daemon::Supervisor>(rig, domain::SupervisionSettings{}, shaker, [](const daemon::RigTransition& t) {
    if (std::getenv("HYSTLAB_TRACE"))
      std::fprintf(stderr, "%.3f %s -> %s: %s\n", t.t, std::string(daemon::to_string(t.from)).c_str(), std::string(daemon::to_string(t.to)).c_str(),
                   t.reason.c_str());
  });
  daemon::RunnerContext ctx{rig, *b.sup, *b.writer, b.clock};
  ctx.time_scale = scale;
  ctx.now_iso = [] { return std::string("2026-11-23T00:00:00Z"); };
  if (c) ctx.next_control = [c] { return c->pop(); };
  return ctx;
}
// Limits for the envelope tests: -1..5 mm, 100 N, and the rate limit given.
[[maybe_unused]] domain::Limits envelope_limits(double rate_mm_s) {
  domain::Limits l;
  l.displacement_min_mm = -1;
  l.displacement_max_mm = 5;
  l.force_max_N = 100;
  l.rate_max_mm_s = rate_mm_s;
  return l;
}

// A campaign as the daemon hands it over: the plan within the rig's envelope (the defaults).
[[maybe_unused]] daemon::RunnerResult run(std::int64_t id, const domain::Plan& plan, daemon::RunnerContext& ctx) {
  daemon::CampaignJob j;
  j.id = id;
  j.plan = plan;
  j.plan.limits = domain::check_plan_against(plan, domain::RigEnvelope{}, domain::SupervisionSettings{}, plan.kind == domain::CampaignKind::sine);
  return daemon::run_campaign(j, ctx);
}
[[maybe_unused]] std::string end_of(const daemon::RunnerResult& r) { return daemon::to_string(r.end); }
}  // namespace
}  // namespace hystlab::test
