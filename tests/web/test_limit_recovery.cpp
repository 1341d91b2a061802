// A load frame pushed out of its stroke (hystlab-sim's `fault overtravel`: the hand set's jog, a
// specimen giving way) trips its limit and latches. A reset cannot clear that while the frame is
// beyond; POST /api/rigs/NAME/recover brings it back at the safe rate through the controller's
// limit recovery, and an e-stop pressed on the way wins. Real daemon, real hystlab-sim over Modbus
// TCP, real HTTP client.
#include <doctest/doctest.h>

#include <cmath>

#include "../drivers/sim_process.hpp"
#include "api_fixture.hpp"

using namespace hystlab;
using namespace hystlab::test;

namespace {
constexpr double kTimeScale = 5;

json rig(httplib::Client& c) {
  const auto r = c.Get("/api/rigs/sim%20frame");
  REQUIRE(r);
  return json::parse(r->body);
}

// The fastest the frame moved over a second of rig time in the daemon's samples [from, head), in
// mm per rig second: over a window, as the envelope judges the rate (two samples' times are the
// host's clock at each poll, 50 ms of wall time apart here, so a few ms of scheduling between a
// poll's stamp and its answer read as 5 % of speed between two samples, never over a second).
double fastest(LiveDaemon& ld, std::uint64_t from) {
  std::vector<control::LiveSample> s;
  (void)ld.control->read_live(0, from, 1, s);
  double v = 0;
  std::size_t j = 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    j = std::max(j, k + 1);
    while (j < s.size() && s[j].t - s[k].t < 1.0) ++j;
    if (j == s.size()) break;
    v = std::max(v, std::fabs(s[j].frame().displacement_mm - s[k].frame().displacement_mm) / (s[j].t - s[k].t));
  }
  return v;
}
}  // namespace

TEST_CASE(
    "limit recovery: a frame beyond its stroke is refused a reset, brought back by recover at the safe rate, then runs a campaign; "
    "an e-stop on the way back wins") {
  SimProcess sim({"--port", "0", "--time-scale", std::to_string(kTimeScale), "--noise", "0"});
  LiveDaemon ld([&](daemon::DaemonConfig& c) {
    const json cfg{
        {"rigs", {{{"name", "sim frame"}, {"transport", "modbus-tcp"}, {"host", "127.0.0.1"}, {"port", sim.modbus_port}, {"time_scale", kTimeScale}}}}};
    c.rigs = daemon::parse_daemon_config(cfg, ".").rigs;
  });
  auto c = ld.client();
  c.set_read_timeout(40, 0);
  REQUIRE(ld.wait_json("/api/rigs/sim%20frame", [](const json& j) { return j["state"] == "idle"; }));
  CHECK(c.Post("/api/rigs/sim%20frame/recover", "", "application/json")->status == 409);  // nothing to recover

  REQUIRE(sim.control("fault overtravel 13").rfind("ok", 0) == 0);
  REQUIRE(ld.wait_json(
      "/api/rigs/sim%20frame", [](const json& j) { return j["latched"] == true && j["recoverable"] == true; }, 30));
  const json tripped = rig(c);
  CAPTURE(tripped.dump());
  CHECK(tripped["status"]["limit_tripped"] == true);
  CHECK(tripped["sample"]["displacement_mm"].get<double>() > 12.0);

  const auto reset = c.Post("/api/rigs/sim%20frame/reset", "", "application/json");
  REQUIRE(reset);
  CAPTURE(reset->body);
  CHECK(reset->status == 409);
  CHECK(json::parse(reset->body)["reason"].get<std::string>().find("/recover") != std::string::npos);

  const std::uint64_t from = ld.control->live_head(0);
  const auto back = c.Post("/api/rigs/sim%20frame/recover", "", "application/json");
  REQUIRE(back);
  CAPTURE(back->body);
  CHECK(back->status == 200);
  const json a = json::parse(back->body);
  CHECK(a["latched"] == false);
  CHECK(a["state"] == "idle");
  CHECK(a["reason"].get<std::string>().find("back within its stroke") != std::string::npos);
  const json after = rig(c);
  CHECK(after["sample"]["displacement_mm"].get<double>() == doctest::Approx(9.5).epsilon(0.01));  // 0.5 mm inside the ±10 mm stroke
  CHECK(after["status"]["limit_tripped"] == false);
  const double v = fastest(ld, from);
  MESSAGE("recovered from " << tripped["sample"]["displacement_mm"] << " mm in " << a["waited_ms"] << " ms; fastest " << v << " mm/s");
  CHECK(v <= 1.05);  // the safe rate, 1 mm/s
  CHECK(v >= 0.8);   // and it moved at it (2.5 mm and more: windows of a second were there)

  // The rig runs the next campaign as any other.
  json plan = fot_plan(2, 2.0);
  plan["limits"]["displacement_mm"] = {-0.5, 10};
  plan["limits"]["force_N"] = 1500;  // the spring pulls 980 N at 9.5 mm
  const auto sub = c.Post("/api/campaigns", json{{"plan", plan}}.dump(), "application/json");
  REQUIRE(sub);
  REQUIRE(sub->status == 201);
  const std::string id = std::to_string(json::parse(sub->body)["id"].get<std::int64_t>());
  json ended;
  REQUIRE(ld.wait_json(
      "/api/campaigns/" + id, [&](const json& j) { return ended = j, j["final"] == true; }, 120));
  CAPTURE(ended.dump());
  CHECK(ended["state"] == "completed");

  // Out the other side, and an e-stop while it comes back: latched, nothing moves after it.
  REQUIRE(sim.control("fault overtravel -13").rfind("ok", 0) == 0);
  // Tripped, not merely outside the configured ±10 mm on the way out (recoverable too, but pushed on).
  REQUIRE(ld.wait_json(
      "/api/rigs/sim%20frame", [](const json& j) { return j["recoverable"] == true && j["latched"] == true; }, 30));
  const double start = rig(c)["sample"]["displacement_mm"].get<double>();
  struct Joined : std::thread {  // joined on every way out, a failed REQUIRE's too
    using std::thread::thread;
    ~Joined() {
      if (joinable()) join();
    }
  };
  Joined recover([&] {
    auto c2 = ld.client();
    c2.set_read_timeout(40, 0);
    const auto r = c2.Post("/api/rigs/sim%20frame/recover", "", "application/json");  // CHECKs only off the main thread
    CHECK(r);
    if (!r) return;
    CAPTURE(r->body);
    CHECK(r->status == 409);
    CHECK(json::parse(r->body)["reason"].get<std::string>().find("e-stop") != std::string::npos);
  });
  REQUIRE(ld.wait_json(
      "/api/rigs/sim%20frame", [&](const json& j) { return j["sample"]["displacement_mm"].get<double>() > start + 0.3; }, 30));
  const auto stop = c.Post("/api/rigs/sim%20frame/estop", "", "application/json");
  recover.join();
  REQUIRE(stop);
  CHECK(stop->status == 200);
  const double at = rig(c)["sample"]["displacement_mm"].get<double>();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // 1.5 rig seconds: it stays
  const json held = rig(c);
  CHECK(held["state"] == "estopped");
  CHECK(std::fabs(held["sample"]["displacement_mm"].get<double>() - at) < 0.01);
}
