// The acquisition thread's error boundary (daemon/src/rig_worker.cpp: contain()): an exception
// escaping a campaign's loop (injected here in the loop's period, where a strategy's bug would
// throw) holds the rig and disables it, fails the campaign with the reason stored, leaves the
// worker able to go on, and the next campaign runs to completion. In process: the rig's real
// worker and supervisor, the fake controller, the fake clock, a real writer and SQLite file.
#include <doctest/doctest.h>

#include <stdexcept>
#include <string>

#include "safety_world.hpp"

using namespace hystlab;

namespace {
nlohmann::json small_plan() {
  return {{"kind", "fot"}, {"range_mm", {0, 1}}, {"subdivisions", 2}, {"ramp_rate_mm_s", 2}, {"dwell_s", 0.05}, {"sample_rate_hz", 500}, {"validation", false}};
}
}  // namespace

TEST_CASE("contain: an exception on the acquisition thread holds the rig, fails the campaign with the reason, and the next campaign runs") {
  for (const int throw_at : {5, 60, 250}) {  // arming, the first ramp, late in the rows (a run of about 400 periods)
    CAPTURE(throw_at);
    test::SafetyWorld world(false, 1 << 14);
    world.idle(3);
    const auto first = world.job(small_plan());
    int ticks = 0, ticks_after = 0;
    bool thrown = false;
    const auto r = world.run(first, [&] {
      if (++ticks == throw_at) {
        thrown = true;
        throw std::runtime_error("injected: a strategy's bug");
      }
    });
    REQUIRE(thrown);
    CHECK(r.end == daemon::CampaignEnd::failed);
    CHECK(r.reason.find("injected: a strategy's bug") != std::string::npos);
    // Held and disabled at once: the boundary disarmed it before anything else ran.
    CHECK_FALSE(world.rig->enabled());
    CHECK(world.rig->held());
    CHECK_FALSE(world.w.supervisor->latched());
    CHECK(world.w.running_campaign == 0);
    world.writer->flush();
    const auto row = world.store->campaign(first.id);
    REQUIRE(row);
    CHECK(row->state == domain::CampaignState::failed);
    CHECK(world.store->state_reason(first.id, domain::CampaignState::failed) == "error on the acquisition thread: injected: a strategy's bug; the rig is held");
    // The worker goes on: idle ticks, then a campaign to its end.
    world.idle(5);
    const int setpoints_before = static_cast<int>(world.rig->log.setpoints.size());
    const auto second = world.job(small_plan());
    const auto r2 = world.run(second, [&] { ++ticks_after; });
    CHECK(ticks_after > 250);  // the run the throws were placed in
    CHECK(static_cast<int>(world.rig->log.setpoints.size()) > setpoints_before);
    const auto done = world.finish(false);
    REQUIRE(done);
    CHECK(done->end == daemon::CampaignEnd::completed);
    CHECK(r2.end == daemon::CampaignEnd::completed);
    world.writer->flush();
    CHECK(world.store->campaign(second.id)->state == domain::CampaignState::completed);
    CHECK(world.rig->log.setpoints_while_latched == 0);
  }
}
