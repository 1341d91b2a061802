// The rig's supervision over the API, with a real daemon, its simulator and a real HTTP client:
// the operator's e-stop and reset, the envelope at submission, and an abort while another
// process holds the database's write lock.
#include <doctest/doctest.h>

#include "api_fixture.hpp"
#include "hystlab/db/store.hpp"

using namespace hystlab;
using test::json;
using test::LiveDaemon;

namespace {
json waveform(std::vector<double> pts, double rate = 1.0) {
  return {{"kind", "waveform"}, {"points_mm", pts}, {"ramp_rate_mm_s", rate}, {"sample_rate_hz", 500}};
}
std::int64_t submit(httplib::Client& c, const json& plan, int expect = 201) {
  auto r = c.Post("/api/campaigns", json{{"plan", plan}}.dump(), "application/json");
  REQUIRE(r);
  CAPTURE(r->body);
  REQUIRE(r->status == expect);
  return expect == 201 ? json::parse(r->body)["id"].get<std::int64_t>() : 0;
}
}  // namespace

TEST_CASE("operator e-stop from the API latches the rig; a campaign is refused until reset; after the reset one completes") {
  LiveDaemon ld;
  auto c = ld.client();
  REQUIRE(ld.wait_json("/api/rigs/sim%20frame", [](const json& j) { return j["state"] == "idle"; }));
  auto r = c.Post("/api/rigs/sim%20frame/estop", "", "application/json");
  REQUIRE(r);
  CAPTURE(r->body);
  // 200 once latched and confirmed by the rig, never before; or, when the controller lost the
  // write's answer (hystlab-sim misses its 50 ms on a loaded machine: stop 50's last clean clone),
  // 503 "rig unreachable" as docs/API.md says, the latch held in the daemon all the same and the
  // e-stop written again at the rig's next answer: the state below is the rig's either way.
  if (r->status == 503) {
    CHECK(json::parse(r->body)["error"] == "rig unreachable");
  } else {
    CHECK(r->status == 200);
    CHECK(json::parse(r->body)["latched"] == true);
    CHECK(json::parse(r->body)["state"] == "estopped");
  }
  REQUIRE(ld.wait_json(
      "/api/rigs/sim%20frame", [](const json& j) { return j["state"] == "estopped" && j["latched"] == true; }, 10));
  const auto refused = c.Post("/api/campaigns", json{{"plan", waveform({0, 1})}}.dump(), "application/json");
  REQUIRE(refused);
  CHECK(refused->status == 400);
  CHECK(refused->body.find("reset it first") != std::string::npos);
  r = c.Post("/api/rigs/sim%20frame/reset", "", "application/json");
  REQUIRE(r);
  CAPTURE(r->body);
  CHECK(r->status == 200);
  // A second reset finds nothing to reset: 409 with the reason.
  const auto again = c.Post("/api/rigs/sim%20frame/reset", "", "application/json");
  REQUIRE(again);
  CHECK(again->status == 409);
  CHECK(again->body.find("nothing to reset") != std::string::npos);
  REQUIRE(ld.wait_json(
      "/api/rigs/sim%20frame", [](const json& j) { return j["state"] == "idle" && j["latched"] == false; }, 10));
  const auto id = submit(c, waveform({0, 1.0, 0.5}));
  CHECK(ld.wait_json("/api/campaigns/" + std::to_string(id), [](const json& j) { return j["state"] == "completed"; }));
  // The rig view says what a lab engineer checks first.
  const auto rig = json::parse(c.Get("/api/rigs/sim%20frame")->body);
  CHECK(rig["status"]["ready"] == true);
  CHECK(rig["envelope"]["speed_mm_s"] == 20.0);
  CHECK(rig["supervision"]["in_position_mm"] == 0.01);
  CHECK(rig["transitions"].size() >= 3);
  const auto metrics = c.Get("/metrics")->body;
  CHECK(metrics.find("hystlab_rig_state{rig=\"sim frame\",state=\"idle\"} 1") != std::string::npos);
}

TEST_CASE("a plan beyond the rig's envelope is refused at submission, the field and both numbers named") {
  LiveDaemon ld;
  auto c = ld.client();
  auto r = c.Post("/api/campaigns", json{{"plan", waveform({0, 1}, 500)}}.dump(), "application/json");
  REQUIRE(r);
  CHECK(r->status == 400);
  CHECK(r->body.find("ramp_rate_mm_s 500 exceeds the rig's maximum speed 20 mm/s") != std::string::npos);
  r = c.Post("/api/campaigns", json{{"plan", waveform({0, 400})}}.dump(), "application/json");
  REQUIRE(r);
  CHECK(r->status == 400);
  CHECK(r->body.find("points_mm[1] 400 lies outside the rig's stroke") != std::string::npos);
}

TEST_CASE("another process holds the database's write lock for 8 s: an abort acts at once and the API keeps answering") {
  LiveDaemon ld;
  auto c = ld.client();
  // 0.1 mm/s: 60 rig-seconds, 3 s of wall time at 20 times, for the lock and the abort to come mid-run
  // (at 0.5 mm/s the motion lasted 0.6 s, which a stalled test thread could let end first).
  const auto id = submit(c, waveform({0, 6.0}, 0.1));
  REQUIRE(ld.wait_json("/api/campaigns/" + std::to_string(id), [](const json& j) { return j["state"] == "running"; }));
  std::atomic<bool> locked{false};
  std::thread holder([&] {  // a second connection, as another process's would be
    db::Database other(ld.config.db_path);
    other.exec("BEGIN IMMEDIATE");
    locked = true;
    std::this_thread::sleep_for(std::chrono::seconds(8));
    other.exec("COMMIT");
  });
  while (!locked) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const auto t0 = std::chrono::steady_clock::now();
  auto r = c.Post(("/api/campaigns/" + std::to_string(id) + "/abort").c_str(), "", "application/json");
  REQUIRE(r);
  CHECK(r->status == 202);
  // The rig leaves its run at once: safing (or already idle), long before the lock goes.
  CHECK(ld.wait_json(
      "/api/rigs/sim%20frame", [](const json& j) { return j["state"] == "safing" || j["state"] == "idle"; }, 3));
  CHECK(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(4));
  auto status = c.Get("/api/status");
  REQUIRE(status);
  CHECK(status->status == 200);
  holder.join();
  CHECK(ld.wait_json(
      "/api/campaigns/" + std::to_string(id), [](const json& j) { return j["state"] == "aborted"; }, 30));
}
