#pragma once
// One rig as the daemon holds it, in process: the rig's worker (its stop channel, supervisor and
// live feed, the code hystlabd runs), an in-process fake controller, a fake clock, a real SQLite
// file behind the real writer thread. Campaigns run through run_campaign as the rig's thread runs
// them, with the stop channel serviced every period; between campaigns the rig's idle step runs.
// Fast and deterministic: time moves only when the loop sleeps.
#include <unistd.h>

#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "../support/temp_dir.hpp"
#include "fake_rig.hpp"
#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/daemon/supervisor.hpp"
#include "hystlab/domain/envelope.hpp"
#include "rig_worker.hpp"

namespace hystlab::test {

struct SafetyWorld {
  SafetyWorld(bool shaker, std::size_t ring_slots) {
    path = (dir / "hystlab.db").string();
    store = std::make_unique<db::Store>(path);
    writer = std::make_unique<db::SampleWriter>(path, db::WriterOptions{ring_slots, 0.05, 50'000, false});
    rig_id = store->upsert_rig("fake", "{}", "t");
    auto r = std::make_unique<FakeRig>();
    rig = r.get();
    rig->shaker = shaker;
    rig->heartbeat_timeout_s = 0.5;  // the controller's host watchdog, as the embedded simulator's
    rig->enable_delay_s = 0.02;      // the handshake waits 10 periods for `enabled`
    w.rig = std::move(r);
    w.entry.name = "fake";
    w.info.name = "fake";
    w.info.kind = shaker ? domain::RigKind::shaker : domain::RigKind::load_frame;
    w.supervisor = std::make_unique<daemon::Supervisor>(*w.rig, settings, shaker, [this](const daemon::RigTransition& t) { w.record(t); });
    t0 = clock.now();
  }
  ~SafetyWorld() {
    writer.reset();
    store.reset();
  }
  SafetyWorld(const SafetyWorld&) = delete;
  SafetyWorld& operator=(const SafetyWorld&) = delete;

  [[nodiscard]] double rig_time() { return clock.now() - t0; }

  // n idle periods of 50 ms, as the rig's thread runs them between campaigns.
  void idle(int n) {
    rig->t_base = 0;
    for (int k = 0; k < n; ++k) {
      clock.advance(0.05);
      daemon::idle_step(w, rig_time(), "", clock.now());
    }
  }

  daemon::CampaignJob job(const nlohmann::json& plan_json) {
    daemon::CampaignJob j;
    j.plan = domain::parse_plan(plan_json);
    j.plan.limits = domain::check_plan_against(j.plan, domain::RigEnvelope{}, settings, rig->shaker);
    j.id = store->create_campaign(rig_id, j.plan.kind, plan_json.dump(), "t");
    return j;
  }

  // Runs the campaign as rig_thread does (an escaped exception contained there); each_tick is
  // called on every period of the loop (arming included), before the period's controls are read.
  daemon::RunnerResult run(const daemon::CampaignJob& j, const std::function<void()>& each_tick) {
    daemon::RunnerContext ctx(*w.rig, *w.supervisor, *writer, clock);
    ctx.now_iso = [] { return std::string("2026-11-25T00:00:00Z"); };
    ctx.live = &w.live;
    ctx.epoch = t0;
    ctx.service = [this](double t) { w.service(t); };
    ctx.next_control = [this, &each_tick]() -> std::optional<daemon::Control> {
      if (each_tick) each_tick();
      if (controls.empty()) return std::nullopt;
      const auto c = controls.front();
      controls.pop_front();
      return c;
    };
    ctx.finish = [this](daemon::FinishJob f) { pending_finish = std::move(f); };
    rig->t_base = clock.now() - t0;  // the fake controller's clock runs on across campaigns
    w.running_campaign = j.id;
    daemon::RunnerResult r;
    try {
      r = daemon::run_campaign(j, ctx);
    } catch (const std::exception& e) {
      daemon::contain(w, *writer, e.what(), rig_time());
      r.end = daemon::CampaignEnd::failed;
      r.reason = std::string("error on the acquisition thread: ") + e.what();
    }
    w.running_campaign = 0;
    w.supervisor->set_time_offset(0.0);
    rig->t_base = 0;
    return r;
  }

  // The finisher's work for the job the loop handed over (nothing when none is pending).
  std::optional<daemon::RunnerResult> finish(bool fail) {
    if (!pending_finish) return std::nullopt;
    daemon::FinishJob f = std::move(*pending_finish);
    pending_finish.reset();
    const auto id = f.campaign;
    try {
      if (fail) throw std::runtime_error("injected: the fits ran out of memory");
      return daemon::finish_campaign(std::move(f), *writer, [] { return std::string("2026-11-25T00:00:01Z"); });
    } catch (const std::exception& e) {  // as the Finisher thread does
      const std::string reason = std::string("finishing failed: ") + e.what();
      writer->post([id, reason](db::Store& s) { s.transition(id, domain::CampaignState::failed, reason, "t"); });
      daemon::RunnerResult r;
      r.end = daemon::CampaignEnd::failed;
      r.reason = reason;
      return r;
    }
  }

  test_support::TempDir tmp{"safety"};
  std::filesystem::path dir = tmp.path();
  std::string path;
  std::unique_ptr<db::Store> store;
  std::unique_ptr<db::SampleWriter> writer;
  std::int64_t rig_id = 0;
  domain::SupervisionSettings settings;
  daemon::FakeClock clock;
  double t0 = 0;
  FakeRig* rig = nullptr;
  daemon::RigWorker w;
  std::deque<daemon::Control> controls;
  std::optional<daemon::FinishJob> pending_finish;
};

}  // namespace hystlab::test
