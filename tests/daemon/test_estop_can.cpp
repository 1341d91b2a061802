// The operator's e-stop over CAN against hystlab-sim, through the rig's stop channel (the code
// hystlabd runs) with the real CAN driver over a socketpair (the kernel here has no AF_CAN).
#include <doctest/doctest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <future>
#include <optional>
#include <thread>

#include "../drivers/sim_process.hpp"
#include "campaign_bench.hpp"
#include "hystlab/drivers/can_rig.hpp"
#include "hystlab/protocols/signals.hpp"
#include "rig_worker.hpp"

using namespace hystlab;
using hystlab::test::SimProcess;
using namespace hystlab::test;

// The operator's e-stop over CAN (the real driver over a socketpair to hystlab-sim, real time):
// pressed through the rig's stop channel, as the API presses it, in five phases of a campaign.
TEST_CASE("operator e-stop over CAN in every phase: written within two periods, confirmed by the status word, the campaign aborted") {
  int sv[2];
  REQUIRE(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv) == 0);
  SimProcess sim({"--transport", "can", "--can-fd", "3", "--can-rate", "1000", "--time-scale", "1", "--noise", "0"}, sv[1]);
  close(sv[1]);
  daemon::RigWorker w;
  w.rig = std::make_unique<drivers::CanRig>(std::make_unique<drivers::FdCanChannel>(sv[0], "socketpair"), drivers::CanRigConfig{});
  w.info.kind = domain::RigKind::load_frame;
  w.entry.name = "can frame";
  w.supervisor = std::make_unique<daemon::Supervisor>(*w.rig, domain::SupervisionSettings{}, false, [&w](const daemon::RigTransition& t) { w.record(t); });
  Bench b;
  daemon::SteadyClock clock;
  const double t0 = clock.now();
  auto rig_time = [&] { return clock.now() - t0; };
  auto idle = [&](int n) {
    for (int k = 0; k < n; ++k) {
      daemon::idle_step(w, rig_time(), "", clock.now());
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  };
  idle(5);
  const nlohmann::json plan_json{
      {"kind", "fot"},  {"range_mm", {0, 2}},    {"subdivisions", 2},   {"ramp_rate_mm_s", 1.0},
      {"dwell_s", 0.5}, {"sample_rate_hz", 500}, {"validation", false}, {"limits", {{"displacement_mm", {-0.5, 2.5}}, {"force_N", 400}, {"rate_mm_s", 20}}}};
  using P = daemon::CampaignPhase;
  for (const std::string phase : {"just submitted", "ramping", "dwelling", "paused", "safing"}) {
    CAPTURE(phase);
    Controls controls;
    const auto plan = domain::parse_plan(plan_json);
    const auto id = b.submit(plan.source);
    daemon::CampaignJob j;
    j.id = id;
    j.plan = plan;
    j.plan.limits = domain::check_plan_against(plan, domain::RigEnvelope{}, domain::SupervisionSettings{}, false);
    daemon::RunnerContext ctx{*w.rig, *w.supervisor, *b.writer, clock};
    ctx.now_iso = [] { return std::string("2026-11-25T00:00:00Z"); };
    ctx.next_control = [&controls] { return controls.pop(); };
    ctx.service = [&w](double t) { w.service(t); };
    ctx.live = &w.live;
    ctx.epoch = t0;
    std::optional<std::future<control::CommandOutcome>> answer;
    if (phase == "just submitted") answer = w.push_rig_command(control::RigCommand::estop);
    daemon::RunnerResult r;
    std::thread loop([&] { r = daemon::run_campaign(j, ctx); });
    auto phase_now = [&] { return static_cast<P>(w.live.phase.load()); };
    auto wait_phase = [&](P p, double min_x) {
      for (int k = 0; k < 20000; ++k) {
        std::vector<control::LiveSample> last;
        const auto h = w.live.ring.head();
        if (h > 0) (void)w.live.ring.read(h - 1, 1, last);
        if (phase_now() == p && !last.empty() && last.back().frame().displacement_mm >= min_x) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      return false;
    };
    if (phase == "ramping") REQUIRE(wait_phase(P::ramping, 0.3));
    if (phase == "dwelling") REQUIRE(wait_phase(P::dwelling, 0.9));
    if (phase == "paused") {
      REQUIRE(wait_phase(P::ramping, 0.3));
      controls.push(daemon::Control::pause);
      REQUIRE(wait_phase(P::paused, 0));
    }
    if (phase == "safing") {
      REQUIRE(wait_phase(P::dwelling, 0.9));
      controls.push(daemon::Control::abort);
      REQUIRE(wait_phase(P::safing, 0));
    }
    const std::uint64_t head = w.live.ring.head();
    const double pressed = clock.now();
    if (!answer) answer = w.push_rig_command(control::RigCommand::estop);
    loop.join();
    idle(3);  // the rig's thread is idle again: the status word confirms the e-stop there
    REQUIRE(answer->wait_for(std::chrono::seconds(2)) == std::future_status::ready);
    const control::CommandOutcome o = answer->get();
    CHECK(o.result == control::CommandOutcome::Result::done);
    CHECK(o.confirmed);
    CHECK(r.end == daemon::CampaignEnd::aborted);
    CHECK(r.reason.find("e-stop by the operator") != std::string::npos);
    // From the samples the loop read after the press: the e-stop bit within a few periods, and
    // the frame where it was (1 mm/s: 2 periods of 2 ms are 4 µm).
    std::vector<control::LiveSample> after;
    (void)w.live.ring.read(head > 0 ? head - 1 : 0, 1, after);
    REQUIRE_FALSE(after.empty());
    const double x0 = after.front().frame().displacement_mm;
    double moved = 0, seen = -1;
    for (const auto& s : after) {
      moved = std::max(moved, std::fabs(s.frame().displacement_mm - x0));
      if (seen < 0 && (s.status & protocols::status::estop)) seen = s.mono_s - pressed;
    }
    const double x0_age = pressed - after.front().mono_s;
    MESSAGE(phase << ": e-stop in the status word " << seen * 1e3 << " ms after the press; moved " << moved << " mm");
    CHECK(seen >= 0);
    // The latency is the scheduler's (the rig's thread and hystlab-sim must both run): measured in
    // stop 44 over 20 runs of this test (100 presses) in the ASan tree with stress-ng --cpu 1
    // beside it, median 7.5 ms, 95th percentile 28 ms, worst 164 ms (paused, the frame held); the
    // bound is 3 times the worst, as the API's twin's (tests/web/test_estop_phases.cpp). Moved at
    // most 0.003 mm then. The frame moves
    // at the plan's 1 mm/s from the last sample before the press until the e-stop shows in the
    // status word, then stops within the controller's own 0.02 mm. (A fixed 0.02 mm failed the
    // API's twin in stop 42 when a host stall put the e-stop 54.6 ms after the request.)
    CHECK(seen < 0.5);
    CHECK(moved < 1.0 * (x0_age + seen) + 0.02);
    w.supervisor->set_time_offset(0.0);
    auto reset = w.push_rig_command(control::RigCommand::reset);
    // The reset is confirmed by a status read on the rig's thread: served until it is (5 s at most).
    for (int k = 0; k < 250 && reset.wait_for(std::chrono::seconds(0)) != std::future_status::ready; ++k) idle(1);
    REQUIRE(reset.wait_for(std::chrono::seconds(0)) == std::future_status::ready);
    CHECK(reset.get().result == control::CommandOutcome::Result::done);
  }
}
