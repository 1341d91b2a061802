// The supervisor and the one acquisition loop, with a fake clock and an in-process fake rig:
// every supervision rule, fast and without sleeping; and seeded randomized fault schedules that
// CAPTURE their input and check the invariants (never moving while latched, never armed without
// `enabled`, every campaign ending in a terminal state with the rig held or disabled).
#include <doctest/doctest.h>
#include <unistd.h>

#include <deque>
#include <filesystem>
#include <random>

#include "../support/temp_dir.hpp"
#include "fake_rig.hpp"
#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/daemon/online_fot.hpp"
#include "hystlab/daemon/sequencer.hpp"
#include "hystlab/daemon/supervisor.hpp"
#include "hystlab/domain/envelope.hpp"

namespace fs = std::filesystem;
using namespace hystlab;
using daemon::CampaignEnd;
using daemon::RigState;
using test::FakeRig;
using test::FaultEvent;

namespace {
struct Harness {
  explicit Harness(domain::SupervisionSettings s = {}) : settings(s) {
    path = (dir / "hystlab.db").string();
    store = std::make_unique<db::Store>(path);
    writer = std::make_unique<db::SampleWriter>(path, db::WriterOptions{1U << 16, 0.05, 50'000, false});
    rig_id = store->upsert_rig("fake", "{}", "t");
    sup = std::make_unique<daemon::Supervisor>(rig, settings, false, [this](const daemon::RigTransition& t) { transitions.push_back(t); });
  }
  ~Harness() {
    writer.reset();
    store.reset();
  }
  daemon::CampaignJob job(const nlohmann::json& plan_json) {
    daemon::CampaignJob j;
    j.plan = domain::parse_plan(plan_json);
    j.plan.limits = domain::check_plan_against(j.plan, envelope, settings, false);
    j.id = store->create_campaign(rig_id, j.plan.kind, plan_json.dump(), "t");
    return j;
  }
  daemon::RunnerResult run(const daemon::CampaignJob& j, std::function<void(double)> each_tick = {}) {
    daemon::RunnerContext ctx(rig, *sup, *writer, clock);
    ctx.now_iso = [] { return std::string("2026-11-24T00:00:00Z"); };
    ctx.next_control = [this]() -> std::optional<daemon::Control> {
      if (tick_hook) tick_hook(clock.now() - start);
      if (controls.empty()) return std::nullopt;
      const auto c = controls.front();
      controls.pop_front();
      return c;
    };
    tick_hook = std::move(each_tick);
    start = clock.now();
    auto r = daemon::run_campaign(j, ctx);
    writer->flush();
    return r;
  }
  std::string state_of(std::int64_t id) { return domain::to_string(store->campaign(id)->state); }
  bool saw(RigState to) const {
    for (const auto& t : transitions)
      if (t.to == to) return true;
    return false;
  }

  FakeRig rig;
  daemon::FakeClock clock;
  domain::SupervisionSettings settings;
  domain::RigEnvelope envelope;
  test_support::TempDir tmp{"super"};
  fs::path dir = tmp.path();
  std::string path;
  std::unique_ptr<db::Store> store;
  std::unique_ptr<db::SampleWriter> writer;
  std::int64_t rig_id = 0;
  std::unique_ptr<daemon::Supervisor> sup;
  std::vector<daemon::RigTransition> transitions;
  std::deque<daemon::Control> controls;
  std::function<void(double)> tick_hook;
  double start = 0;
};

nlohmann::json waveform(std::vector<double> points, double rate = 2.0) {
  return {{"kind", "waveform"}, {"points_mm", points}, {"ramp_rate_mm_s", rate}, {"sample_rate_hz", 1000}};
}
daemon::StatusView ok_status(bool enabled) {
  return {static_cast<std::uint16_t>(protocols::status::ready | (enabled ? protocols::status::enabled : 0U)), 0, 0.0};
}
}  // namespace

TEST_CASE("supervisor: the first answer re-asserts held and disabled; e-stop and faults latch until a reset that the rig confirms") {
  Harness h;
  CHECK(h.sup->state() == RigState::disconnected);
  CHECK_FALSE(h.sup->on_status(0.0, ok_status(false)));
  CHECK(h.sup->state() == RigState::idle);
  CHECK(h.rig.held());
  // The rig's own e-stop: latched in the supervisor, arming refused with the reason.
  const auto why = h.sup->on_status(0.1, {static_cast<std::uint16_t>(protocols::status::estop), 3, 0.0});
  REQUIRE(why);
  CHECK(why->find("e-stop") != std::string::npos);
  CHECK(h.sup->state() == RigState::estopped);
  const auto refusal = h.sup->begin_arming(0.2);
  REQUIRE(refusal);
  CHECK(refusal->find("reset it first") != std::string::npos);
  // A reset the rig does not confirm (it still reports the e-stop) is refused after its time.
  h.sup->begin_reset(0.3);
  CHECK(h.rig.log.resets == 1);
  (void)h.sup->on_status(0.4, {static_cast<std::uint16_t>(protocols::status::estop), 3, 0.0});
  (void)h.sup->on_status(0.3 + h.settings.reset_timeout_s + 0.1, {static_cast<std::uint16_t>(protocols::status::estop), 3, 0.0});
  CHECK(h.sup->latched());
  CHECK(h.sup->reset_refusal().find("still reports") != std::string::npos);
  // Confirmed: ready, no e-stop: the latch clears.
  h.sup->begin_reset(5.0);
  (void)h.sup->on_status(5.1, ok_status(false));
  CHECK(h.sup->state() == RigState::idle);
  CHECK_FALSE(h.sup->latched());
}

TEST_CASE("supervisor: a fault code is named with the map's text; a latched rig is never commanded") {
  Harness h;
  (void)h.sup->on_status(0.0, ok_status(false));
  const auto why = h.sup->on_status(0.1, {static_cast<std::uint16_t>(protocols::status::fault), 7, 0.0});
  REQUIRE(why);
  CHECK(*why == "rig fault: fault 7 (hydraulic pressure low), not ready");
  CHECK(h.sup->fault_code() == 7);
  CHECK(h.sup->state() == RigState::faulted);
}

TEST_CASE("arming handshake: mode written, enabled required in time, a rig not ready refused with its reason") {
  SUBCASE("a rig in another mode never reports enabled: the campaign fails at the arm timeout, nothing moved") {
    Harness h;
    h.rig.required_mode = 2;  // the supervisor writes mode 1
    const auto j = h.job(waveform({0, 2, 0}));
    const auto r = h.run(j);
    CHECK(r.end == CampaignEnd::failed);
    CHECK(r.reason.find("did not report enabled") != std::string::npos);
    CHECK(h.rig.log.mode_writes >= 1);
    CHECK(h.rig.position() == doctest::Approx(0.0));
    CHECK(h.state_of(j.id) == "failed");
    CHECK_FALSE(h.saw(RigState::armed));
  }
  SUBCASE("answers lost while arming: the handshake is written again and the campaign runs") {
    Harness h;
    h.rig.late_mode_answers = 3;
    const auto j = h.job(waveform({0, 1, 0}));
    const auto r = h.run(j);
    CHECK(r.end == CampaignEnd::completed);
    CHECK(h.rig.log.mode_writes >= 4);
    CHECK(h.saw(RigState::armed));
  }
  SUBCASE("a controller that never answers the handshake fails at the arm deadline, saying so and how often it was asked") {
    Harness h;
    h.rig.late_mode_answers = 1'000'000;
    const auto j = h.job(waveform({0, 1, 0}));
    const auto r = h.run(j);
    CHECK(r.end == CampaignEnd::failed);
    CAPTURE(r.reason);
    CHECK(r.reason.find("cannot write mode 1: timeout") != std::string::npos);
    CHECK(r.reason.find(" attempts)") != std::string::npos);
    CHECK(h.rig.log.mode_writes > 10);
    CHECK(h.rig.log.enable_writes == 0);
    CHECK(h.rig.position() == doctest::Approx(0.0));
    CHECK_FALSE(h.saw(RigState::armed));
  }
  SUBCASE("the link lost between two handshakes: nothing is written again, the rig is never enabled, the reason says so") {
    Harness h;
    h.rig.late_mode_answers = 30;                            // the first ~10 ticks' handshakes lose their answer ...
    h.rig.plan.push_back({FaultEvent::drop, 0.01, 0.3, 0});  // ... then the link is gone for 0.29 s
    const auto r = h.run(h.job(waveform({0, 1, 0})));
    CHECK(r.end == CampaignEnd::failed);
    CAPTURE(r.reason);
    CHECK(r.reason.find("lost while arming") != std::string::npos);
    CHECK(h.rig.log.enable_writes == 0);
    CHECK_FALSE(h.rig.enabled());
    CHECK_FALSE(h.saw(RigState::armed));
  }
  SUBCASE("a rig with a latched fault is not armed") {
    Harness h;
    h.rig.plan.push_back({FaultEvent::latch_fault, 0.0, 0.0, 7});
    const auto r = h.run(h.job(waveform({0, 2, 0})));
    CHECK(r.end == CampaignEnd::failed);
    CHECK(r.reason.find("fault 7 (hydraulic pressure low)") != std::string::npos);
    CHECK(h.rig.log.enables_while_latched == 0);
    CHECK_FALSE(h.saw(RigState::armed));
  }
}

TEST_CASE("loop: a waveform completes; the rig ends held and disabled; every sample published") {
  Harness h;
  const auto j = h.job(waveform({0, 1.5, 0.5}));
  const auto r = h.run(j);
  CHECK(r.end == CampaignEnd::completed);
  CHECK(h.state_of(j.id) == "completed");
  CHECK(r.samples > 1000);
  CHECK(r.gaps == 0);
  CHECK(h.rig.position() == doctest::Approx(0.5).epsilon(0.02));
  CHECK_FALSE(h.rig.enabled());
  CHECK(h.sup->state() == RigState::idle);
  CHECK(h.store->sample_count(r.run_id) == static_cast<std::int64_t>(r.samples));
}

TEST_CASE("loop: a fault latched mid-campaign fails it within 3 sample periods, held, the reason names the code") {
  Harness h;
  h.rig.plan.push_back({FaultEvent::latch_fault, 0.8, 0.0, 7});
  const auto j = h.job(waveform({0, 3, 0}));
  const auto r = h.run(j);
  CHECK(r.end == CampaignEnd::failed);
  CHECK(r.reason.find("fault 7 (hydraulic pressure low)") != std::string::npos);
  // The fault became visible at 0.8 s of rig time: the last sample stored (the one showing it)
  // is within 3 sample periods of it.
  double last_t = 0;
  h.store->for_each_sample(r.run_id, 0, 1LL << 40, [&](const db::SampleRow& row) { last_t = std::max(last_t, row.t); });
  CHECK(last_t >= 0.8);
  CHECK(last_t <= 0.8 + 3 * 0.001 + 1e-9);
  CHECK(h.sup->state() == RigState::faulted);
  CHECK(h.rig.held());
  CHECK(h.rig.log.setpoints_while_latched == 0);
}

TEST_CASE("loop: a dead band beyond the in-position tolerance fails the segment at its deadline; within it, completes") {
  SUBCASE("0.02 mm dead band, 0.01 mm tolerance") {
    Harness h;
    h.rig.deadband_mm = 0.02;
    const auto r = h.run(h.job(waveform({0, 2.0})));
    CHECK(r.end == CampaignEnd::failed);
    CHECK(r.reason.find("target 2.000 mm not reached") != std::string::npos);
    CHECK(r.reason.find("stopped at 1.98") != std::string::npos);
    CHECK(h.rig.held());
    // The deadline: 2 mm at 2 mm/s, plus lag, settle and the host-stall allowance (at 1 kHz).
    const double deadline_s = 2.0 / 2.0 + h.settings.lag_s + h.settings.settle_s + domain::kHostStallAllowance_s;
    CHECK(static_cast<double>(r.samples) < (deadline_s + 0.1) * 1000);
    CHECK(static_cast<double>(r.samples) > (deadline_s - 0.1) * 1000);
  }
  SUBCASE("0.005 mm dead band") {
    Harness h;
    h.rig.deadband_mm = 0.005;
    CHECK(h.run(h.job(waveform({0, 2.0}))).end == CampaignEnd::completed);
  }
}

TEST_CASE("loop: abort ramps to the safe position, sampled and published, and ends within the tolerance") {
  Harness h;
  const auto j = h.job(waveform({0, 3.0, 0.0}, 1.0));
  bool sent = false;
  const auto r = h.run(j, [&](double t) {
    if (!sent && t > 2.0) h.controls.push_back(daemon::Control::abort), sent = true;
  });
  CHECK(r.end == CampaignEnd::aborted);
  CHECK(std::fabs(h.rig.position() - j.plan.limits.safe_position_mm) <= h.settings.in_position_mm);
  CHECK(h.saw(RigState::safing));
  CHECK(h.state_of(j.id) == "aborted");
}

TEST_CASE("loop: a lost link holds the rig, the hold is written again the moment it answers, and a failed campaign leaves it held") {
  Harness h;
  h.rig.plan.push_back({FaultEvent::drop, 1.0, 4.0, 0});  // 3 s without a link, mid-ramp
  const auto j = h.job(waveform({0, 4.0}, 1.0));
  const auto r = h.run(j);
  CHECK(r.end == CampaignEnd::failed);
  CHECK(r.reason.find("watchdog") != std::string::npos);
  CHECK_FALSE(h.rig.held());  // the link is still down: nothing could be written yet
  // The link comes back: the first answer re-asserts held and disabled before anything else.
  drivers::RigSample s;
  const double t = 5.0;
  REQUIRE_FALSE(h.rig.read_sample(t, s));
  (void)h.sup->on_status(t, {s.status_word, s.fault_code, s.displacement_mm});
  CHECK(h.rig.held());
  CHECK_FALSE(h.rig.enabled());
  const double x = h.rig.position();
  REQUIRE_FALSE(h.rig.read_sample(t + 2.0, s));
  CHECK(s.displacement_mm == doctest::Approx(x));  // not moving
}

TEST_CASE("loop: the operator's e-stop reaches the rig at once and latches") {
  Harness h;
  bool sent = false;
  const auto r = h.run(h.job(waveform({0, 3.0})), [&](double t) {
    if (!sent && t > 0.5) h.controls.push_back(daemon::Control::estop), sent = true;
  });
  CHECK(r.end == CampaignEnd::aborted);
  CHECK(h.rig.latched());
  CHECK(h.sup->state() == RigState::estopped);
  CHECK(h.rig.log.estop_writes == 1);
}

TEST_CASE("randomized fault schedules: never moving while latched, never armed without enabled, always a terminal state") {
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> when(0.0, 3.0), len(0.0, 1.2);
    Harness h;
    std::string schedule;
    const int n = static_cast<int>(rng() % 4);
    for (int k = 0; k < n; ++k) {
      const auto kind = static_cast<FaultEvent::Kind>(rng() % 6);
      const double at = when(rng);
      h.rig.plan.push_back({kind, at, at + len(rng), static_cast<std::uint16_t>(1 + rng() % 9)});
      schedule += std::to_string(static_cast<int>(kind)) + "@" + std::to_string(at) + " ";
    }
    if (rng() % 3 == 0) h.rig.deadband_mm = 0.02;
    CAPTURE(schedule);
    const auto j = h.job(waveform({0, 2.0, 0.5}, 2.0));
    bool armed_without_enabled = false, moved_while_latched = false;
    double latched_x = NAN;
    const auto r = h.run(j, [&](double) {
      if (h.sup->state() == RigState::armed && !h.rig.enabled() && !h.rig.latched() && !h.rig.held() && h.rig.moving()) armed_without_enabled = true;
      if (h.sup->latched()) {
        if (std::isnan(latched_x)) latched_x = h.rig.position();
        if (std::fabs(h.rig.position() - latched_x) > 0.05) moved_while_latched = true;
      }
    });
    CHECK(r.end != CampaignEnd::none);
    const std::string st = h.state_of(j.id);
    CHECK((st == "completed" || st == "failed" || st == "aborted"));
    CHECK_FALSE(armed_without_enabled);
    CHECK_FALSE(moved_while_latched);
    CHECK(h.rig.log.setpoints_while_latched == 0);
    CHECK(h.rig.log.enables_while_latched == 0);
    bool armed_seen = false;
    for (const auto& t : h.transitions)
      if (t.to == RigState::armed) armed_seen = true;
    if (armed_seen) CHECK(h.rig.log.mode_writes >= 1);
    CHECK((h.sup->state() == RigState::idle || h.sup->latched() || h.sup->state() == RigState::disconnected || h.sup->state() == RigState::holding));
  }
}

// A FOT row 3 on a 0..4 mm grid of 4 cells: up to 3 mm, then down to 0 in 0.1 mm steps 10 ms
// apart, with one jump from `from` to `to` taking `jump_s`. Returns the β of each node found.
std::vector<double> fot_row_with_jump(double spacing, double from, double to, double jump_s, bool* pending_at_bottom = nullptr) {
  std::vector<double> betas;
  daemon::OnlineFot fot(models::Grid::make(0, 4, 4), 0.02, [&](const models::FotNode& n, double) { betas.push_back(n.beta); });
  fot.set_spacing(spacing);
  double t = 0;
  for (int k = 0; k <= 30; ++k) fot.feed(t += 0.01, 0.1 * k, 10.0 * k, true);
  for (int k = 29; k >= 0; --k) {
    const double x = 0.1 * k;
    if (x < from - 1e-9 && x > to + 1e-9) continue;  // inside the jump: not sampled
    t += std::fabs(x - to) < 1e-9 ? jump_s : 0.01;
    fot.feed(t, x, 5.0 * k, true);
  }
  if (pending_at_bottom) *pending_at_bottom = fot.bottom_pending(3);
  for (int k = 1; k <= 5; ++k) fot.feed(t += 0.01, 0.1 * k, 0.0, true);  // the next rise turns the bottom
  return betas;
}

TEST_CASE("online FOT: a node inside a hole in the data is left missing, not interpolated; coarse regular sampling is no hole") {
  bool pending = false;
  CHECK(fot_row_with_jump(0.01, 0.0, 0.0, 0.01, &pending) == std::vector<double>{2, 1, 0});  // no jump
  CHECK(pending);                                                                            // δ1 passed, the bottom (δ0) waits for the next reversal
  // 2.3 -> 1.6 mm in 0.5 s: node δ2 = 2 mm is inside the hole.
  CHECK(fot_row_with_jump(0.01, 2.3, 1.6, 0.5) == std::vector<double>{1, 0});
  // The same jump at the regular spacing (coarse sampling, not late): interpolated.
  CHECK(fot_row_with_jump(0.01, 2.3, 1.6, 0.01) == std::vector<double>{2, 1, 0});
  // Offline data (no spacing given): every crossing is interpolated, as before.
  CHECK(fot_row_with_jump(0.0, 2.3, 1.6, 0.5) == std::vector<double>{2, 1, 0});
}

TEST_CASE("sequencer: in position once within the tolerance, then the dwell runs") {
  daemon::Sequencer seq({{1.0, 2.0, 0.5, daemon::SegmentKind::waypoint, 0}, {0.0, 2.0, 0.0, daemon::SegmentKind::waypoint, 0}}, 0.01);
  REQUIRE(seq.step(0.0, 0.0));  // the first command
  CHECK_FALSE(seq.in_position());
  CHECK_FALSE(seq.step(0.3, 0.6));
  CHECK_FALSE(seq.in_position());
  CHECK_FALSE(seq.step(0.6, 0.995));
  CHECK(seq.in_position());
  CHECK(seq.index() == 0);
  CHECK_FALSE(seq.step(1.0, 1.0));  // dwelling until 1.1
  const auto next = seq.step(1.2, 1.0);
  REQUIRE(next);
  CHECK(next->target_mm == 0.0);
  CHECK_FALSE(seq.in_position());
}
