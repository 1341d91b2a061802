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
    // 20 rounds beside the shaker's real-time tests and stress-ng --cpu 1 (stop 42; how:
    // tests/daemon/test_shaker_campaign.cpp's `figure`): worst 0.8 % off of 80.
    MESSAGE("figure api_prediction_over_ratio " << p["predicted_ratio"].get<double>() / p["ratio"].get<double>());
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
  MESSAGE("figure api_base_envelope_mm " << base);  // 0.00612-0.00614 mm in those 20 rounds
  CHECK(base > 0.004);                              // the base envelope: the demand, with the steps' starting transients
  CHECK(base < 0.008);
}

TEST_CASE("the mission's chain: springs identified on the simulated load frame predict the simulated isolator on the simulated shaker") {
  // Both simulators carry the same spring (Table 1's simplified model): the frame's specimen and
  // each of the shaker's four, preloaded to 0.80 mm by the 13 kg mass. The frame identifies it
  // over 0-2 mm (n = 16: cells of 0.125 mm around the 0.80 mm preload), and the shaker's sweep
  // names that stored table as its isolator's springs (tolerances below, with what was seen).
  test::LiveDaemon live([](daemon::DaemonConfig& c) {
    c.rigs = daemon::parse_daemon_config(json{{"rigs",
                                               {{{"name", "sim frame"}, {"simulate", {{"time_scale", 1}, {"noise_N", 0.05}}}},
                                                {{"name", "sim shaker"}, {"simulate", {{"rig", "shaker"}, {"time_scale", 1}}}}}}})
                 .rigs;
  });
  auto c = live.client();
  json fot = test::fot_plan(16, 4.0);  // in real time, read in blocks: every sample of the nodes' approach
  fot["range_mm"] = {0, 2};
  fot["limits"]["displacement_mm"] = {-0.5, 2.5};
  auto r = c.Post("/api/campaigns", json{{"plan", fot}, {"rig", "sim frame"}}.dump(), "application/json");
  REQUIRE(r);
  REQUIRE(r->status == 201);
  const std::string frame_id = std::to_string(json::parse(r->body)["id"].get<std::int64_t>());
  REQUIRE(live.wait_json(
      "/api/campaigns/" + frame_id, [](const json& j) { return j["state"] == "completed" && j["recommendation"].is_object(); }, 240));
  // The FOT table itself (the recommendation may be the least-squares one, whose small loops are
  // its prior's, not the measured cells').
  std::int64_t table = 0;
  const json frame = json::parse(c.Get(("/api/campaigns/" + frame_id).c_str())->body);
  for (const json& t : frame["tables"])
    if (t["method"] == "fot") table = t["id"];
  REQUIRE(table > 0);

  // "resonance": the steps refined around the peak until its half-power band holds 5 points, so
  // that the resonance is compared as a frequency (measured and predicted at the same steps),
  // not as a ratio on its flanks, where the ratio changes about 140 % a hertz (Q 25, 0.4 Hz off
  // the peak) and a table's 1.5 % spread in small-loop stiffness moves it 20 %.
  const json plan{{"kind", "sine"},
                  {"frequencies_hz", {10, 15, 17, 18.5, 24}},
                  {"amplitude_mm", 0.005},
                  {"settle", {{"change", "1 %"}, {"consecutive", 2}}},
                  {"measured_cycles", 8},
                  {"resonance", true},
                  {"isolator", {{"table", table}}}};
  json missing = plan;  // a table the store does not hold: refused, named, before anything moves
  missing["isolator"]["table"] = table + 1000;
  r = c.Post("/api/campaigns", json{{"plan", missing}, {"rig", "sim shaker"}}.dump(), "application/json");
  REQUIRE(r);
  CHECK(r->status == 400);
  CAPTURE(r->body);
  CHECK(json::parse(r->body)["field"] == "plan.isolator.table");
  CHECK(json::parse(r->body)["detail"].get<std::string>().find("which this daemon's store does not hold") != std::string::npos);
  r = c.Post("/api/campaigns", json{{"plan", plan}, {"rig", "sim shaker"}}.dump(), "application/json");
  REQUIRE(r);
  REQUIRE(r->status == 201);
  const std::string id = std::to_string(json::parse(r->body)["id"].get<std::int64_t>());
  REQUIRE(live.wait_json(
      "/api/campaigns/" + id, [](const json& j) { return j["state"] == "completed"; }, 300));
  const json pts = json::parse(c.Get(("/api/campaigns/" + id + "/transmissibility").c_str())->body);
  REQUIRE(pts.size() > 5);  // the planned steps and the refinement's
  for (const json& p : pts) {
    CAPTURE(p.dump());
    REQUIRE(p["predicted_ratio"].is_number());
    // Measured against predicted from the frame's table, off the resonance (10, 15, 24 Hz): the
    // same order (within a factor of 1.5). Both identifications run in real time, so how close
    // they agree depends on how the machine treats them that minute: 0.1-3.5 % off on quiet runs,
    // 10.6 % at 15 Hz under ThreadSanitizer beside other tests (issue 40), where the simulator's
    // holes reach the frame's table; 0.940-1.068 over 57 steps in stop 42's 20 loaded rounds
    // (3 times the worst deviation, 0.2, is inside the factor 1.5). The agreement is printed per step.
    const double f = p["frequency_hz"].get<double>(), ratio = p["predicted_ratio"].get<double>() / p["ratio"].get<double>();
    MESSAGE("the chain at " << f << " Hz: predicted " << p["predicted_ratio"].get<double>() << ", measured " << p["ratio"].get<double>());
    if (f < 16 || f > 21) MESSAGE("figure chain_prediction_over_measured " << ratio);
    if (f < 16 || f > 21) {
      CHECK(ratio > 1 / 1.5);
      CHECK(ratio < 1.5);
    }
  }
  // The resonance, measured and predicted at the same steps: within 0.4 Hz (2 %; seen 0.005 to
  // 0.113 Hz over stop 42's 20 loaded rounds, the peak 0.89-1.07 of the measured: 3 times the
  // worst of each is inside 0.4 Hz and 35 %), measured 17.65 Hz each time: the n = 16 table's small-loop
  // stiffness at the 0.80 mm preload varies about 1.5 % from one identification to the next,
  // 0.75 % in frequency), its peak within 35 % (seen -6 to +17 %: at 5 µm the damping is the
  // table's interpolation inside its 0.125 mm cells, which a Q of 25 shows whole).
  const json sweep = json::parse(c.Get(("/api/campaigns/" + id + "/sweep").c_str())->body);
  const json& measured = sweep["measured"]["curves"][0]["resonance"];
  const json& predicted = sweep["predicted"]["curves"][0]["resonance"];
  CAPTURE(measured.dump());
  CAPTURE(predicted.dump());
  REQUIRE(measured.is_object());
  REQUIRE(predicted.is_object());
  CHECK(measured["resolved"] == true);
  MESSAGE("the chain's resonance: measured " << measured.dump() << ", predicted " << predicted.dump());
  MESSAGE("figure chain_resonance_difference_hz " << std::fabs(measured["frequency_hz"].get<double>() - predicted["frequency_hz"].get<double>()));
  MESSAGE("figure chain_peak_over_measured " << predicted["peak_ratio"].get<double>() / measured["peak_ratio"].get<double>());
  CHECK(std::fabs(measured["frequency_hz"].get<double>() - predicted["frequency_hz"].get<double>()) < 0.4);
  CHECK(std::fabs(predicted["peak_ratio"].get<double>() / measured["peak_ratio"].get<double>() - 1) < 0.35);
  // The provenance with the prediction: which table, how identified, from which campaign.
  const json events = json::parse(c.Get(("/api/campaigns/" + id + "/events").c_str())->body);
  std::string with;
  for (const json& e : events)
    if (e["kind"] == "sweep_done") with = e["detail"]["predicted_with"];
  CAPTURE(with);
  CHECK(with.find("Preisach table n = 16 (fot,") != std::string::npos);
  CHECK(with.find("table " + std::to_string(table) + ": campaign " + frame_id) != std::string::npos);
}

TEST_CASE("a refusal from the daemon's main loop crosses to the HTTP thread whole, request after request") {
  // The isolator's table is looked up on the main loop; its refusal is an exception carried back
  // to the HTTP thread that reads its message. That exception was once freed by the main loop
  // while the HTTP thread still read it (ThreadSanitizer, CI): 40 refusals in a row, each whole.
  test::LiveDaemon live([](daemon::DaemonConfig& c) {
    c.rigs = daemon::parse_daemon_config(json{{"rigs", {{{"name", "sim shaker"}, {"simulate", {{"rig", "shaker"}}}}}}}).rigs;
  });
  auto c = live.client();
  const json plan{{"kind", "sine"}, {"frequencies_hz", {10}}, {"amplitude_mm", 0.005}, {"isolator", {{"table", 4242}}}};
  for (int k = 0; k < 40; ++k) {
    CAPTURE(k);
    auto r = c.Post("/api/campaigns", json{{"plan", plan}, {"rig", "sim shaker"}}.dump(), "application/json");
    REQUIRE(r);
    REQUIRE(r->status == 400);
    const json e = json::parse(r->body);
    CHECK(e["field"] == "plan.isolator.table");
    CHECK(e["detail"].get<std::string>().find("4242") != std::string::npos);
  }
  CHECK(json::parse(c.Get("/api/campaigns")->body).empty());  // nothing stored for a refused plan
}
