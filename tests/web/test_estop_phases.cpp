// The operator's e-stop against a real daemon and hystlab-sim over Modbus TCP in real time (time
// scale 1), pressed through the API in the phases where it used to wait for the campaign to end:
// just submitted, ramping, dwelling at a top, paused, and on the safe ramp of an abort. Each press
// must be answered only once latched and confirmed by the rig's status word, end the campaign
// aborted, and leave the frame where it was (measured from the samples the daemon read: the
// controller's own view). Then a reset clears it and the next phase runs.
#include <doctest/doctest.h>

#include <cmath>

#include "../support/daemon_process.hpp"
#include "api_fixture.hpp"
#include "hystlab/db/store.hpp"
#include "hystlab/protocols/signals.hpp"

using namespace hystlab;
using namespace hystlab::test;

namespace {

json plan() {  // a preamble at 0 mm (dwell 1 s), a rise to 1 mm, a dwell there, descents: about 12 s
  return json{
      {"kind", "fot"},  {"range_mm", {0, 2}},    {"subdivisions", 2},   {"ramp_rate_mm_s", 1.0},
      {"dwell_s", 1.0}, {"sample_rate_hz", 500}, {"validation", false}, {"limits", {{"displacement_mm", {-0.5, 2.5}}, {"force_N", 400}, {"rate_mm_s", 20}}}};
}

struct Press {
  int status = 0;
  json answer;
  double seconds = 0;        // from the request to the answer
  double moved_mm = 0;       // from the last sample before the request to the farthest within 1 s after it
  double estop_seen_s = -1;  // from the request to the first sample whose status word shows the e-stop
  double x0_age_s = 0;       // how long before the request that last sample was acquired
};

// The daemon's live samples (as read from the rig) in [from, head).
std::vector<control::LiveSample> samples(LiveDaemon& ld, std::uint64_t from) {
  std::vector<control::LiveSample> out;
  (void)ld.control->read_live(0, from, 1, out);
  return out;
}

Press press(LiveDaemon& ld) {
  Press p;
  auto c = ld.client();
  const std::uint64_t head = ld.control->live_head(0);
  const auto before = samples(ld, head > 0 ? head - 1 : 0);
  const double x0 = before.empty() ? 0.0 : before.back().frame().displacement_mm;
  const double t0 = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  p.x0_age_s = before.empty() ? 0.0 : std::max(0.0, t0 - before.back().mono_s);
  const auto r = c.Post("/api/rigs/sim%20frame/estop", "", "application/json");
  p.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count() - t0;
  REQUIRE(r);
  p.status = r->status;
  p.answer = json::parse(r->body);
  std::this_thread::sleep_for(std::chrono::seconds(1));
  for (const control::LiveSample& s : samples(ld, head)) {
    if (s.mono_s < t0) continue;
    p.moved_mm = std::max(p.moved_mm, std::fabs(s.frame().displacement_mm - x0));
    if (p.estop_seen_s < 0 && (s.status & protocols::status::estop)) p.estop_seen_s = s.mono_s - t0;
  }
  return p;
}

std::string phase_of(LiveDaemon& ld) {
  auto c = ld.client();
  const auto r = c.Get("/api/rigs/sim%20frame");
  return r && r->status == 200 ? json::parse(r->body).value("phase", "") : "";
}

bool wait_phase(LiveDaemon& ld, const std::string& phase, double seconds, const std::function<bool()>& also = {}) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (phase_of(ld) == phase && (!also || also())) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

double position(LiveDaemon& ld) {
  const std::uint64_t head = ld.control->live_head(0);
  const auto s = samples(ld, head > 0 ? head - 1 : 0);
  return s.empty() ? 0.0 : s.back().frame().displacement_mm;
}

std::int64_t submit(httplib::Client& c) {
  const auto r = c.Post("/api/campaigns", json{{"plan", plan()}}.dump(), "application/json");
  REQUIRE(r);
  REQUIRE(r->status == 201);
  return json::parse(r->body)["id"].get<std::int64_t>();
}
}  // namespace

TEST_CASE(
    "operator e-stop in every phase of a campaign (hystlabd, hystlab-sim over Modbus, real time): latched and confirmed before the answer, "
    "the campaign aborted, the frame stopped") {
  LiveDaemon ld([](daemon::DaemonConfig& c) {
    c.rigs[0].sim.time_scale = 1.0;
    c.rigs[0].sim.noise_N = 0.0;
  });
  auto c = ld.client();
  REQUIRE(ld.wait_json("/api/rigs/sim%20frame", [](const json& j) { return j["state"] == "idle"; }));
  const std::vector<std::string> phases{"just submitted", "ramping", "dwelling", "paused", "safing"};
  for (const std::string& phase : phases) {
    CAPTURE(phase);
    const std::int64_t id = submit(c);
    if (phase == "ramping") REQUIRE(wait_phase(ld, "ramping", 20, [&] { return position(ld) > 0.3; }));
    if (phase == "dwelling") REQUIRE(wait_phase(ld, "dwelling", 20, [&] { return position(ld) > 0.9; }));
    if (phase == "paused") {
      REQUIRE(wait_phase(ld, "ramping", 20, [&] { return position(ld) > 0.3; }));
      REQUIRE(c.Post(("/api/campaigns/" + std::to_string(id) + "/pause").c_str(), "", "application/json"));
      REQUIRE(wait_phase(ld, "paused", 10));
    }
    if (phase == "safing") {
      REQUIRE(wait_phase(ld, "dwelling", 20, [&] { return position(ld) > 0.9; }));
      REQUIRE(c.Post(("/api/campaigns/" + std::to_string(id) + "/abort").c_str(), "", "application/json"));
      REQUIRE(wait_phase(ld, "safing", 10, [&] { return position(ld) < 0.8; }));
    }
    const Press p = press(ld);
    CAPTURE(p.answer.dump());
    MESSAGE(phase << ": answered in " << p.seconds * 1e3 << " ms; e-stop in the status word " << p.estop_seen_s * 1e3 << " ms after the request; moved "
                  << p.moved_mm << " mm after it");
    CHECK(p.status == 200);  // never 202 "armed": answered once latched and seen in the status word
    CHECK(p.answer["latched"] == true);
    CHECK(p.answer["confirmed"] == true);
    CHECK(p.answer["state"] == "estopped");
    CHECK(p.seconds < 1.0);
    CHECK(p.estop_seen_s >= 0);
    CHECK(p.estop_seen_s < 0.5);
    // The frame moves at the plan's 1 mm/s until the controller stops it: from the last sample
    // before the request until the e-stop shows in the status word, then within 0.05 mm for the
    // controller's own stop (it was 0.7-1.0 mm in 0.6 s when the press waited for the campaign).
    // The latency is the scheduler's, bounded above (< 0.5 s): stop 42's warm clean-clone run saw
    // the e-stop 54.6 ms after the request while ramping and 0.056 mm moved, against a fixed
    // 0.05 mm bound then; quiet runs see 2-6 ms and under 0.01 mm.
    CHECK(p.moved_mm < 1.0 * (p.x0_age_s + p.estop_seen_s) + 0.05);
    CHECK(ld.wait_json(
        "/api/campaigns/" + std::to_string(id), [](const json& j) { return j["final"] == true; }, 30));
    const json camp = json::parse(c.Get(("/api/campaigns/" + std::to_string(id)).c_str())->body);
    CHECK((camp["state"] == "aborted" || camp["state"] == "failed"));
    CHECK(camp["reason"].get<std::string>().find("e-stop") != std::string::npos);  // why, beside the state
    const json listed = json::parse(c.Get("/api/campaigns")->body);
    CHECK(listed.back()["reason"] == camp["reason"]);
    // Its report says how it ended and why.
    const std::string report = c.Get(("/api/campaigns/" + std::to_string(id) + "/report.html").c_str())->body;
    CHECK(report.find("<span class=\"state\">" + camp["state"].get<std::string>() + "</span> " + camp["reason"].get<std::string>()) != std::string::npos);
    const auto reset = c.Post("/api/rigs/sim%20frame/reset", "", "application/json");
    REQUIRE(reset);
    CAPTURE(reset->body);
    CHECK(reset->status == 200);
    REQUIRE(ld.wait_json(
        "/api/rigs/sim%20frame", [](const json& j) { return j["state"] == "idle" && j["latched"] == false; }, 10));
  }
}

TEST_CASE("the documented commands as written: curl -d '' reaches the e-stop; a command that does not apply answers 409 with the reason") {
  LiveDaemon ld;
  auto c = ld.client();
  REQUIRE(ld.wait_json("/api/rigs/sim%20frame", [](const json& j) { return j["state"] == "idle"; }));
  // curl -s -X POST -d '' "$H/api/rigs/sim%20frame/estop": a form content type with an empty body.
  auto r = c.Post("/api/rigs/sim%20frame/estop", "", "application/x-www-form-urlencoded");
  REQUIRE(r);
  CHECK(r->status == 200);
  CHECK(json::parse(r->body)["latched"] == true);
  r = c.Post("/api/rigs/sim%20frame/reset", "", "application/x-www-form-urlencoded");
  REQUIRE(r);
  CHECK(r->status == 200);
  // A body that is not JSON still is refused (a cross-site form cannot carry one).
  r = c.Post("/api/rigs/sim%20frame/estop", "a=1", "application/x-www-form-urlencoded");
  REQUIRE(r);
  CHECK(r->status == 415);
  // Resume a running campaign: 409, and what does apply.
  const auto id = submit(c);
  REQUIRE(ld.wait_json(
      "/api/campaigns/" + std::to_string(id), [](const json& j) { return j["state"] == "running"; }, 30));
  r = c.Post(("/api/campaigns/" + std::to_string(id) + "/resume").c_str(), "", "application/json");
  REQUIRE(r);
  CHECK(r->status == 409);
  CHECK(r->body.find("'resume' does not apply (pause, abort, estop do)") != std::string::npos);
  r = c.Post(("/api/campaigns/" + std::to_string(id) + "/abort").c_str(), "", "application/json");
  REQUIRE(r);
  CHECK(r->status == 202);
  CHECK(ld.wait_json(
      "/api/campaigns/" + std::to_string(id), [](const json& j) { return j["state"] == "aborted"; }, 30));
}

TEST_CASE(
    "kill -9 loses at most 250 ms of samples wherever it lands (hystlabd at 1 kHz in real time: preamble, training, ramping, "
    "dwelling, paused, validation, safing)") {
  for (const std::string phase : {"preamble", "training", "ramping", "dwelling", "paused", "validation", "safing"}) {
    CAPTURE(phase);
    test_support::DaemonProcess d(R"({"rigs": [{"name": "sim frame", "simulate": {"time_scale": 1, "noise_N": 0}}]})");
    httplib::Client c("127.0.0.1", d.port());
    c.set_read_timeout(10, 0);
    json p = plan();
    p["sample_rate_hz"] = 1000;
    p["training_cycles"] = 1;
    p["validation"] = {{"reversals", 2}};
    auto r = c.Post("/api/campaigns", json{{"plan", p}}.dump(), "application/json");
    REQUIRE(r);
    REQUIRE(r->status == 201);
    auto rig = [&] { return json::parse(c.Get("/api/rigs/sim%20frame")->body); };
    auto wait_for = [&](const std::string& ph) {
      for (int k = 0; k < 8000; ++k) {  // the validation run comes after about 20 s
        if (rig().value("phase", "") == ph) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      return false;
    };
    if (phase == "paused" || phase == "safing") {
      REQUIRE(wait_for("ramping"));
      if (phase == "safing") std::this_thread::sleep_for(std::chrono::milliseconds(800));  // 0.8 mm up: a safe ramp of 0.8 s
      REQUIRE(c.Post(phase == "paused" ? "/api/campaigns/1/pause" : "/api/campaigns/1/abort", "", "application/json"));
    }
    REQUIRE(wait_for(phase));
    // Some batches committed in the phase (the preamble's dwell and the abort's ramp are short).
    std::this_thread::sleep_for(std::chrono::milliseconds(phase == "preamble" || phase == "safing" ? 100 : 300));
    const json now = rig();
    REQUIRE(now["sample"].is_object());
    const double acquired_t = now["sample"]["t"].get<double>();
    d.kill9();
    db::Store s(d.db_path());
    db::Statement st(s.database(), "SELECT max(t) FROM samples WHERE run_id IN (SELECT id FROM runs WHERE campaign_id = 1)");
    REQUIRE(st.step());
    const double stored_t = st.column_double(0);
    MESSAGE(phase << ": the newest sample acquired before the kill at " << acquired_t << " s, the newest stored " << stored_t
                  << " s: " << (acquired_t - stored_t) * 1e3 << " ms lost at most");
    CHECK(acquired_t - stored_t <= 0.25);
    CHECK(s.integrity_check() == "ok");
  }
}
