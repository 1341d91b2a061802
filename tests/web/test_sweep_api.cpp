// A sine campaign through the API on a simulated shaker: its points with their predictions, the
// sweep report, the downloads, and the shaker's samples under their own names.
#include <doctest/doctest.h>

#include "api_fixture.hpp"
#include "hystlab/domain/signals.hpp"

using namespace hystlab;
using nlohmann::json;

TEST_CASE("a sweep through the API: points, prediction, resonance report, CSVs with the shaker's own columns") {
  test::LiveDaemon live([](daemon::DaemonConfig& c) {
    c.rigs = daemon::parse_daemon_config(json{{"rigs", {{{"name", "sim shaker"}, {"simulate", {{"rig", "shaker"}, {"time_scale", 0.5}}}}}}}).rigs;
  });
  auto c = live.client();
  const json plan{{"kind", "sine"},     {"frequencies_hz", {10, 20}}, {"direction", "up-down"},           {"amplitude_mm", 0.005},
                  {"settle_cycles", 4}, {"measured_cycles", 4},       {"control", {{"window_cycles", 2}}}};
  auto r = c.Post("/api/campaigns", json{{"plan", plan}, {"rig", "sim shaker"}}.dump(), "application/json");
  REQUIRE(r);
  REQUIRE(r->status == 201);
  const std::string id = std::to_string(json::parse(r->body)["id"].get<std::int64_t>());
  REQUIRE(live.wait_json(
      "/api/campaigns/" + id, [](const json& j) { return j["state"] == "completed"; }, 120));

  const json pts = json::parse(c.Get(("/api/campaigns/" + id + "/transmissibility").c_str())->body);
  REQUIRE(pts.size() == 4);  // 10 and 20 Hz, up then down
  CHECK(pts[0]["direction"] == "up");
  CHECK(pts[3]["direction"] == "down");
  CHECK(pts[3]["frequency_hz"] == 10.0);
  for (const json& p : pts) {
    CAPTURE(p.dump());
    CHECK(p["k"].is_number_integer());
    CHECK(p["of"] == 4);
    CHECK(p["predicted_ratio"].is_number());  // the simulated shaker's isolator, simulated
    CHECK(std::fabs(p["predicted_ratio"].get<double>() / p["ratio"].get<double>() - 1) < 0.1);
  }
  const json sweep = json::parse(c.Get(("/api/campaigns/" + id + "/sweep").c_str())->body);
  REQUIRE(sweep["measured"]["curves"].size() == 2);
  CHECK(sweep["measured"]["curves"][0]["amplitude_mm"] == 0.005);
  CHECK(sweep["measured"]["compared"] == 1);
  CHECK(sweep["predicted"].is_object());
  // The report: the transmissibility and phase as vector graphics, the resonance table, the jumps.
  const auto report = c.Get(("/api/campaigns/" + id + "/report.html").c_str());
  REQUIRE(report);
  CHECK(report->status == 200);
  CHECK(report->get_header_value("Content-Type").find("text/html") == 0);
  for (const char* part : {"<h2>Transmissibility</h2>", "<h3>Resonances</h3>", "<h3>Jumps (up against down)</h3>", "Data quality, per run", "(predicted)"}) {
    CAPTURE(part);
    CHECK(report->body.find(part) != std::string::npos);
  }
  CHECK(std::count(report->body.begin(), report->body.end(), '<') > 100);
  CHECK(report->body.find("<svg") != std::string::npos);
  CHECK(report->body.find("<script") == std::string::npos);  // self-contained, nothing runs
  CHECK(sweep["jump_threshold"] == doctest::Approx(0.10));
  r = c.Get(("/api/campaigns/" + id + "/sweep.csv").c_str());
  REQUIRE(r->status == 200);
  CHECK(r->body.rfind("k,pass,amplitude_mm,direction,frequency_hz,", 0) == 0);
  CHECK(std::count(r->body.begin(), r->body.end(), '\n') == 5);

  const json camp = json::parse(c.Get(("/api/campaigns/" + id).c_str())->body);
  const std::string run = std::to_string(camp["runs"][0]["id"].get<std::int64_t>());
  r = c.Get(("/api/runs/" + run + "/samples.csv").c_str());
  REQUIRE(r->status == 200);
  CHECK(r->body.rfind(domain::csv_header(domain::kShakerSignals), 0) == 0);
  CHECK(r->body.rfind("seq,t_s,drive_frequency_hz,drive_amplitude_mm,base_displacement_mm,mass_displacement_mm,base_accel_m_s2,mass_accel_m_s2,status\n", 0) ==
        0);
  CHECK(std::count(r->body.begin(), r->body.end(), '\n') > 500);
  const json ov = json::parse(c.Get(("/api/runs/" + run + "/samples?points=50").c_str())->body);
  REQUIRE(ov.contains("base_displacement_max_mm"));
  REQUIRE(ov.contains("mass_displacement_max_mm"));
  CHECK_FALSE(ov.contains("force_max_N"));
  double base = 0;
  for (const json& v : ov["base_displacement_max_mm"]) base = std::max(base, v.get<double>());
  CHECK(base > 0.004);  // the base envelope: the demand, with the steps' starting transients
  CHECK(base < 0.008);
}
