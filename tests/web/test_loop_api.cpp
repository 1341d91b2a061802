// A run's loop as the page draws it (every descent of the FOT input a descending branch, with the
// model's force from the server), the preview of a plan, errors naming the plan's field, and
// each run's data quality.
#include <algorithm>
#include <cmath>

#include "api_fixture.hpp"

using namespace hystlab;
using test::json;

namespace {
httplib::Result post_json(httplib::Client& c, const std::string& path, const json& body) { return c.Post(path.c_str(), body.dump(), "application/json"); }

// Branches of x between reversals (a turn counts past 2 % of the range): {x drop, y range} of
// each descending one.
std::vector<std::pair<double, double>> descents(const std::vector<double>& x, const std::vector<double>& y) {
  const auto [x0, x1] = std::minmax_element(x.begin(), x.end());
  const double eps = 0.02 * (*x1 - *x0);
  std::vector<std::pair<double, double>> out;
  std::size_t start = 0, ext = 0;
  int dir = 0;
  auto close = [&](std::size_t a, std::size_t b) {
    if (dir >= 0) return;
    const auto [ylo, yhi] = std::minmax_element(y.begin() + static_cast<std::ptrdiff_t>(a), y.begin() + static_cast<std::ptrdiff_t>(b) + 1);
    out.emplace_back(x[a] - x[b], *yhi - *ylo);
  };
  for (std::size_t k = 1; k < x.size(); ++k) {
    if (dir == 0) {
      if (std::abs(x[k] - x[0]) > eps) dir = x[k] > x[0] ? 1 : -1, ext = k;
      continue;
    }
    if (dir > 0 ? x[k] >= x[ext] : x[k] <= x[ext])
      ext = k;
    else if (std::abs(x[k] - x[ext]) > eps)
      close(start, ext), start = ext, dir = -dir, ext = k;
  }
  close(start, ext);
  return out;
}
}  // namespace

TEST_CASE("a run's loop keeps every descent, with the model's force from the server; a plan's preview; quality") {
  test::LiveDaemon live;
  auto c = live.client();
  // Before any table: the preview predicts from the simplified model; a bad field is named.
  auto r = post_json(c, "/api/plans/preview", {{"plan", test::fot_plan(4)}});
  REQUIRE(r);
  CAPTURE(r->body);
  REQUIRE(r->status == 200);
  json p = json::parse(r->body);
  CHECK(p["nodes"] == 10);
  CHECK(p["peak_speed_mm_s"] == doctest::Approx(1.0));
  CHECK(p["duration_s"].get<double>() > 2 * 4.0);  // at least the four rises and descents of the top row
  CHECK(p["peak_force_N"].get<double>() > 10);
  CHECK(p["force_source"].get<std::string>().find("simplified") != std::string::npos);
  // The rig is a simulator 20x faster than real time: the wall time and what is stored in rig time.
  CHECK(p["time_scale"] == 20);
  CHECK(p["wall_s"].get<double>() == doctest::Approx(p["duration_s"].get<double>() / 20));
  CHECK(p["stored_rate_hz"].get<double>() == doctest::Approx(25));
  CHECK(std::llabs(p["stored_samples"].get<long long>() - p["samples"].get<long long>() / 20) <= 1);
  json bad = test::fot_plan(4);
  bad["ramp_rate_mm_s"] = 1e6;
  r = post_json(c, "/api/plans/preview", {{"plan", bad}});
  REQUIRE(r);
  CHECK(r->status == 400);
  CHECK(json::parse(r->body)["field"] == "plan.ramp_rate_mm_s");
  CHECK(json::parse(r->body)["detail"].get<std::string>().find("0.000100") == std::string::npos);  // numbers as people write them
  r = post_json(c, "/api/campaigns", {{"plan", bad}});
  CHECK(json::parse(r->body)["field"] == "plan.ramp_rate_mm_s");

  const int n = 4;
  json named = test::fot_plan(n);
  named["specimen"] = 42;  // a specimen is text
  r = post_json(c, "/api/campaigns", {{"plan", named}});
  CHECK(r->status == 400);
  CHECK(json::parse(r->body)["field"] == "plan.specimen");
  named["specimen"] = "NiTi spring A7";
  named["notes"] = "second batch, <as received>";
  r = post_json(c, "/api/campaigns", {{"plan", named}});
  REQUIRE(r->status == 201);
  CHECK(json::parse(r->body)["specimen"] == "NiTi spring A7");
  REQUIRE(live.wait_json(
      "/api/campaigns/1", [](const json& j) { return j["state"] == "completed"; }, 120));
  const json camp = json::parse(c.Get("/api/campaigns/1")->body);
  const std::int64_t run = camp["runs"][0]["id"];
  const json q = camp["runs"][0]["quality"];
  REQUIRE(q.is_object());
  CHECK(q["samples"].get<std::int64_t>() > 100);
  CHECK(q["requested_rate_hz"] == 500);
  CHECK(q["warnings"].is_array());
  CHECK(camp["tables"][0]["warnings"].is_array());
  // Quality per run: the campaign's run and the validation run each with its own figures, which
  // count that run's stored samples (until stop 27 the first counted both and the second none).
  REQUIRE(camp["runs"].size() == 2);
  CHECK(camp["runs"][1]["role"] == "validation");
  for (const json& run_j : camp["runs"]) {
    CAPTURE(run_j.dump());
    REQUIRE(run_j["quality"].is_object());
    CHECK(run_j["quality"]["samples"] == run_j["samples"]);
    // the simulator runs 20x faster than real time: 500 Hz of wall time is 25 Hz of rig time, as expected (no warning)
    // (a starved machine misses samples: the rate may fall short, never exceed; and only a rate
    // that falls short of the expected one is warned about). The lower bound is the order of
    // magnitude: the run lasts about a second of wall time, half of which a stall can take.
    const double rate = run_j["quality"]["rate_hz"].get<double>();
    CHECK(rate < 25 * 1.05);
    CHECK(rate > 25 * 0.2);
    CHECK(run_j["quality"]["expected_rate_hz"].get<double>() == doctest::Approx(25));
    bool rate_warned = false;
    for (const json& w : run_j["quality"]["warnings"]) rate_warned = rate_warned || w.get<std::string>().find("of rig time") != std::string::npos;
    CHECK(rate_warned == (std::fabs(rate / 25 - 1) > 0.05));
  }

  // The report: every section, and the numbers the API gives, rounded for people.
  const auto report = c.Get("/api/campaigns/1/report.html");
  REQUIRE(report);
  CHECK(report->status == 200);
  const std::string& html = report->body;
  for (const char* part : {"Campaign #1: FOT identification on sim frame", "<h2>Rig and plan</h2>", "Data quality, per run", "<h2>Identification</h2>",
                           "The Everett table measured by the FOT input", "Tables, scored on the held-out validation run", "Loop figures, per closed cycle",
                           "<h2>Record</h2>", "(recommended)"}) {
    CAPTURE(part);
    CHECK(html.find(part) != std::string::npos);
  }
  CHECK(html.find("<svg") != std::string::npos);
  REQUIRE(camp["recommendation"].is_object());
  CHECK(html.find("Recommended: table #" + std::to_string(camp["recommendation"]["table"].get<int>())) != std::string::npos);
  for (const json& t : camp["tables"]) {
    char rms[32];
    std::snprintf(rms, sizeof rms, "%.3g N", t["accuracy"]["held_out"]["overall"]["rms_N"].get<double>());
    CAPTURE(rms);
    CHECK(html.find(rms) != std::string::npos);  // each table's held-out RMS, as the API gives it
  }
  const json loops = json::parse(c.Get("/api/campaigns/1/loops")->body);
  const std::size_t cycles_at = html.find("Loop figures, per closed cycle");
  std::size_t tr = 0;
  for (std::size_t at = html.find("<tr>", cycles_at); at != std::string::npos && at < html.find("</table>", cycles_at); at = html.find("<tr>", at + 1)) ++tr;
  CHECK(tr == loops.size() + 1);  // a row per closed cycle, and the header
  CHECK(c.Get("/api/campaigns/99/report.html")->status == 404);
  CHECK(html.find("<th>specimen</th><td>NiTi spring A7</td>") != std::string::npos);
  CHECK(html.find("second batch, &lt;as received&gt;") != std::string::npos);  // the lab's words, escaped

  r = c.Get(("/api/runs/" + std::to_string(run) + "/loop?points=400").c_str());
  REQUIRE(r);
  REQUIRE(r->status == 200);
  const json loop = json::parse(r->body);
  const auto x = loop["x"].get<std::vector<double>>(), y = loop["y"].get<std::vector<double>>();
  CHECK(x.size() == y.size());
  CHECK(x.size() <= 400 + loop["reversals"].get<std::size_t>() + 2);
  CHECK(x.size() >= 200);
  CHECK(loop["samples"].get<std::int64_t>() == camp["runs"][0]["samples"].get<std::int64_t>());
  // Each row i of the FOT input descends from δ_i to δmin: n descents at least, each with a real
  // force drop (no vertical line at δ_i).
  const auto [ylo, yhi] = std::minmax_element(y.begin(), y.end());
  const auto branches = descents(x, y);
  CHECK(branches.size() >= static_cast<std::size_t>(n));
  const double y_range = *yhi - *ylo;
  for (const auto& branch : branches) {
    const double dx = branch.first, dy = branch.second;  // plain names: clang 14 cannot capture bindings (CAPTURE is a lambda)
    CAPTURE(dx);
    if (dx > 0.9) CHECK(dy > 0.1 * y_range);  // a grid step is 1 mm
  }
  // The identified model's force, on the same inputs, from the server: close to the measured loop.
  REQUIRE(loop["model"].is_object());
  const auto f = loop["model"]["force_N"].get<std::vector<double>>();
  REQUIRE(f.size() == x.size());
  double se = 0;
  for (std::size_t k = 0; k < f.size(); ++k) se += (f[k] - y[k]) * (f[k] - y[k]);
  CHECK(std::sqrt(se / static_cast<double>(f.size())) < 0.1 * y_range);
  // The preview now predicts from that table.
  p = json::parse(post_json(c, "/api/plans/preview", {{"plan", test::fot_plan(4)}})->body);
  CHECK(p["force_source"].get<std::string>().find("table #") != std::string::npos);
  // Parameters are checked.
  CHECK(c.Get(("/api/runs/" + std::to_string(run) + "/loop?points=1").c_str())->status == 400);
  CHECK(c.Get("/api/runs/999/loop")->status == 404);
}
