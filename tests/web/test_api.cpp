// The HTTP/JSON API over loopback with a real client: a campaign from submission to exported
// tables, the samples (decimated without losing a peak, and as a streamed CSV), evaluation,
// every error path, the token rule, path traversal, and /metrics.
#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "../support/build_paths.hpp"
#include "api_fixture.hpp"
#include "hystlab/models/accuracy.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/preisach_model.hpp"

using namespace hystlab;
using test::json;

namespace {
void check_error(const httplib::Result& r, int status, const std::string& detail_part) {
  REQUIRE(r);
  CAPTURE(r->body);
  CHECK(r->status == status);
  CHECK(r->get_header_value("Content-Type") == "application/json");
  const json j = json::parse(r->body);
  CHECK(j.contains("error"));
  CHECK(j["detail"].get<std::string>().find(detail_part) != std::string::npos);
}

httplib::Result post(httplib::Client& c, const std::string& path, const json& body) { return c.Post(path.c_str(), body.dump(), "application/json"); }
}  // namespace

TEST_CASE("a campaign through the API: submit, follow, nodes, tables and their exports, samples, evaluation") {
  test::LiveDaemon live;
  auto c = live.client();
  auto r = c.Get("/api/status");
  REQUIRE(r);
  CHECK(r->status == 200);
  const json status = json::parse(r->body);
  CHECK(status["version"] == "0.1.0");
  CHECK(status["rigs"][0]["name"] == "sim frame");
  CHECK(!r->has_header("Access-Control-Allow-Origin"));  // no CORS at all

  r = post(c, "/api/campaigns", {{"plan", test::fot_plan(3)}});
  REQUIRE(r);
  REQUIRE(r->status == 201);
  const std::int64_t id = json::parse(r->body)["id"];
  CHECK(r->get_header_value("Location") == "/api/campaigns/" + std::to_string(id));
  REQUIRE(live.wait_json("/api/campaigns/" + std::to_string(id), [](const json& j) { return j["state"] == "completed"; }));

  const json camp = json::parse(c.Get(("/api/campaigns/" + std::to_string(id)).c_str())->body);
  CHECK(camp["progress"]["nodes"] == 6);
  CHECK(camp["progress"]["required"] == 6);
  REQUIRE(camp["runs"].size() == 2);  // the campaign's run, and the validation run after the rows
  CHECK(camp["runs"][0]["role"] == "campaign");
  CHECK(camp["runs"][1]["role"] == "validation");
  REQUIRE(camp["tables"].size() == 2);
  const std::int64_t run = camp["runs"][0]["id"], samples = camp["runs"][0]["samples"];
  CHECK(samples > 100);
  const json nodes = json::parse(c.Get(("/api/campaigns/" + std::to_string(id) + "/nodes").c_str())->body);
  CHECK(nodes["coverage"] == 1.0);
  CHECK(nodes["grid"]["n"] == 3);
  CHECK(json::parse(c.Get(("/api/campaigns/" + std::to_string(id) + "/events").c_str())->body).size() >= 4);

  // Tables: the fot one, exported three ways.
  const std::int64_t table = camp["tables"][0]["id"];
  CHECK(camp["tables"][0]["method"] == "fot");
  r = c.Get(("/api/tables/" + std::to_string(table) + "/export?format=json").c_str());
  REQUIRE(r->status == 200);
  CHECK(r->get_header_value("Content-Disposition").find("hystlab_table_") != std::string::npos);
  const models::TableDocument doc = models::table_from_json(r->body);
  CHECK(doc.table.grid().n == 3);
  r = c.Get(("/api/tables/" + std::to_string(table) + "/export?format=csv").c_str());
  REQUIRE(r->status == 200);
  std::istringstream csv(r->body);
  int rows = 0;
  for (std::string line; std::getline(csv, line);) rows += line.empty() || line[0] == '#' || line[0] == 'i' ? 0 : 1;
  CHECK(rows == 10);  // (n+1)(n+2)/2 nodes
  r = c.Get(("/api/tables/" + std::to_string(table) + "/export?format=m").c_str());
  REQUIRE(r->status == 200);
  CHECK(r->body.find("function f = hystlab_eval(T, x)") != std::string::npos);
  CHECK(r->body.find("T.n = 3;") != std::string::npos);
  // The FMU: a ZIP archive (its local header's signature) holding the model description and the
  // runtime (tests/fmu runs what is inside).
  r = c.Get(("/api/tables/" + std::to_string(table) + "/export?format=fmu").c_str());
  REQUIRE(r->status == 200);
  CHECK(r->get_header_value("Content-Type") == "application/zip");
  CHECK(r->get_header_value("Content-Disposition").find(".fmu") != std::string::npos);
  CHECK(r->body.rfind("PK\x03\x04", 0) == 0);
  CHECK(r->body.find("modelDescription.xml") != std::string::npos);
  CHECK(r->body.find("binaries/linux64/hystlab_element.so") != std::string::npos);
  CHECK(json::parse(c.Get(("/api/tables/" + std::to_string(table)).c_str())->body)["document"]["format"] == "hystlab-everett-table");
  CHECK(json::parse(c.Get("/api/tables")->body).size() == 2);
  CHECK(json::parse(c.Get("/api/campaigns")->body)[0]["tables"] == 2);

  // Samples: the full CSV stream, and a 50-point overview that keeps the extremes.
  r = c.Get(("/api/runs/" + std::to_string(run) + "/samples.csv").c_str());
  REQUIRE(r->status == 200);
  std::istringstream all(r->body);
  std::string line;
  std::getline(all, line);
  CHECK(line == "seq,t_s,command_mm,displacement_mm,force_N,status");
  std::vector<double> x, ts;
  double fmax = -1e300, fmin = 1e300;
  while (std::getline(all, line)) {
    double v[6];
    REQUIRE(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5]) == 6);
    x.push_back(v[3]);
    ts.push_back(v[1]);
    fmax = std::max(fmax, v[4]);
    fmin = std::min(fmin, v[4]);
  }
  CHECK(static_cast<std::int64_t>(x.size()) == samples);
  const json ov = json::parse(c.Get(("/api/runs/" + std::to_string(run) + "/samples?points=50").c_str())->body);
  // 50 equal slices of the run's time span; slices in a gap of the time axis (a starved host)
  // have no samples and no bucket.
  REQUIRE_FALSE(ts.empty());
  const double t0 = *std::min_element(ts.begin(), ts.end()), span = *std::max_element(ts.begin(), ts.end()) - t0;
  std::set<long> slots;
  for (double t : ts) slots.insert(std::clamp(static_cast<long>((t - t0) / span * 50.0), 0L, 49L));
  CHECK(ov["buckets"].get<std::size_t>() == slots.size());
  CHECK(slots.size() >= 10);
  std::int64_t counted = 0;
  for (const auto& k : ov["n"]) counted += k.get<std::int64_t>();
  CHECK(counted == samples);
  const auto& hi = ov["force_max_N"];
  const auto& lo = ov["force_min_N"];
  CHECK(*std::max_element(hi.begin(), hi.end()) == doctest::Approx(fmax).epsilon(1e-6));
  CHECK(*std::min_element(lo.begin(), lo.end()) == doctest::Approx(fmin).epsilon(1e-6));

  // Evaluation: the stored table on the measured displacement, as the library computes it.
  std::vector<double> xs(x.begin(), x.begin() + std::min<std::ptrdiff_t>(2000, static_cast<std::ptrdiff_t>(x.size())));
  r = post(c, "/api/evaluate", {{"table_id", table}, {"displacement_mm", xs}});
  REQUIRE(r->status == 200);
  const json ev = json::parse(r->body);
  models::PreisachModel m(std::make_shared<const models::EverettTable>(doc.table));
  for (std::size_t k = 0; k < xs.size(); ++k) {
    const double f = m.step(xs[k]);
    CAPTURE(k);
    REQUIRE(ev["force_N"][k].get<double>() == f);
  }
  r = post(c, "/api/evaluate", {{"params", {{"model", "simplified-sma"}}}, {"displacement_mm", {0.0, 1.0, 2.0}}});
  CAPTURE(r->body);
  CHECK((r->status == 200 || r->status == 400));  // the parameter format's own rules decide; never a crash

  // Held-out validation: every table scored on the validation run, the lowest error recommended,
  // and the same score again from the API, equal to an independent recomputation from the samples.
  const std::int64_t vrun = camp["runs"][1]["id"];
  CHECK(camp["runs"][1]["samples"].get<std::int64_t>() > 100);
  REQUIRE(camp["recommendation"].is_object());
  const std::int64_t recommended = camp["recommendation"]["table"];
  CHECK(camp["recommendation"]["why"].get<std::string>().find("lowest error on the validation run") != std::string::npos);
  double best = 1e300;
  for (const json& t : camp["tables"]) {
    REQUIRE(t["accuracy"].contains("held_out"));
    best = std::min(best, t["accuracy"]["held_out"]["overall"]["rms_N"].get<double>());
  }
  for (const json& t : camp["tables"]) {
    const std::int64_t tid = t["id"];
    CAPTURE(tid);
    CHECK(t["accuracy"]["recommended"].get<bool>() == (tid == recommended));
    if (tid == recommended) CHECK(t["accuracy"]["held_out"]["overall"]["rms_N"].get<double>() == best);
    r = c.Get(("/api/tables/" + std::to_string(tid) + "/score?run=" + std::to_string(vrun)).c_str());
    REQUIRE(r->status == 200);
    const json score = json::parse(r->body);
    CHECK(score["overall"]["rms_N"].get<double>() == doctest::Approx(t["accuracy"]["held_out"]["overall"]["rms_N"].get<double>()).epsilon(1e-12));
    CHECK(score["descending"]["max_N"].get<double>() == doctest::Approx(t["accuracy"]["held_out"]["descending"]["max_N"].get<double>()).epsilon(1e-12));
    // Independently: the validation run's samples as CSV, the table's document, the library's compare.
    const models::TableDocument td = models::table_from_json(c.Get(("/api/tables/" + std::to_string(tid) + "/export?format=json").c_str())->body);
    std::istringstream vcsv(c.Get(("/api/runs/" + std::to_string(vrun) + "/samples.csv").c_str())->body);
    std::vector<double> vx, vf;
    std::getline(vcsv, line);
    while (std::getline(vcsv, line)) {
      double v[6];
      REQUIRE(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5]) == 6);
      vx.push_back(v[3]);
      vf.push_back(v[4]);
    }
    models::PreisachModel pm(std::make_shared<const models::EverettTable>(td.table));
    std::vector<double> vy(vx.size());
    pm.evaluate(vx, vy);
    const models::AccuracyReport rep = models::compare(vx, vf, vy);
    CHECK(score["overall"]["rms_N"].get<double>() == doctest::Approx(rep.overall.rms).epsilon(1e-6));  // the CSV keeps 9 digits
    CHECK(score["ascending"]["max_N"].get<double>() == doctest::Approx(rep.ascending.max_abs).epsilon(1e-5));
  }
  check_error(c.Get(("/api/tables/" + std::to_string(table) + "/score").c_str()), 400, "run");
  check_error(c.Get(("/api/tables/" + std::to_string(table) + "/score?run=999").c_str()), 404, "no run 999");

  // Loop figures of both runs: the rows' load-unload cycles from δmin and the validation's.
  const json loops = json::parse(c.Get(("/api/campaigns/" + std::to_string(id) + "/loops").c_str())->body);
  REQUIRE(loops.is_array());
  int rows_loops = 0, validation_loops = 0;
  for (const json& l : loops) {
    rows_loops += l["phase"] == "rows";
    validation_loops += l["phase"] == "validation";
    CAPTURE(l.dump());
    CHECK(l["energy_Nmm"].get<double>() > -1.0);
  }
  CHECK(rows_loops >= 3);  // one per row (n = 3)
  CHECK(validation_loops >= 1);
}

TEST_CASE("every error path answers one JSON error with the right status") {
  test::LiveDaemon live;
  auto c = live.client();
  check_error(c.Post("/api/campaigns", "{not json", "application/json"), 400, "not valid JSON");
  check_error(c.Post("/api/campaigns", "[1,2]", "application/json"), 400, "must be a JSON object");
  check_error(post(c, "/api/campaigns", {{"plan", {{"kind", "fot"}, {"range_mm", {0, 4}}}}}), 400, "subdivisions");
  check_error(post(c, "/api/campaigns", {{"plan", test::fot_plan(3)}, {"priority", 1}}), 400, "priority");
  check_error(post(c, "/api/campaigns", {{"plan", test::fot_plan(3)}, {"rig", "frame B"}}), 400, "no rig named 'frame B'");
  json sine{{"kind", "sine"}, {"frequencies_hz", {2, 4}}, {"amplitude_mm", 0.5}};
  check_error(post(c, "/api/campaigns", {{"plan", sine}}), 400, "cannot run on rig");
  check_error(c.Get("/api/campaigns/999"), 404, "no campaign 999");
  check_error(c.Post("/api/campaigns/999/pause"), 404, "no campaign 999");
  check_error(c.Get("/api/runs/999/samples"), 404, "no run 999");
  check_error(c.Get("/api/tables/999/export?format=csv"), 404, "no table 999");
  check_error(c.Get("/api/no/such/thing"), 404, "/api/no/such/thing");
  check_error(c.Get("/api/stream?rig=nope"), 404, "nope");
  check_error(c.Get("/api/stream?last_event_id=1.2"), 400, "Last-Event-ID");
  check_error(c.Get("/api/stream?rate=fast"), 400, "rate");
  check_error(post(c, "/api/evaluate", {{"displacement_mm", {1.0}}}), 400, "exactly one of");
  check_error(post(c, "/api/evaluate", {{"table_id", 1}, {"params", json::object()}, {"displacement_mm", {1.0}}}), 400, "exactly one of");
  check_error(post(c, "/api/evaluate", {{"table", {{"format", "something-else"}}}, {"displacement_mm", {1.0}}}), 400, "");
  check_error(post(c, "/api/evaluate", {{"table_id", 1}, {"displacement_mm", {1.0, "two"}}}), 404, "no table 1");
  // A stored table, for the argument checks that need one.
  REQUIRE(post(c, "/api/campaigns", {{"plan", test::fot_plan(2)}})->status == 201);
  REQUIRE(live.wait_json("/api/campaigns/1", [](const json& j) { return j["state"] == "completed"; }));
  check_error(post(c, "/api/evaluate", {{"table_id", 1}, {"displacement_mm", {1.0, "two"}}}), 400, "displacement_mm[1]");
  check_error(post(c, "/api/evaluate", {{"table_id", 1}, {"displacement_mm", json::array()}}), 400, "displacement_mm");
  check_error(c.Get("/api/tables/1/export?format=xls"), 400, "xls");
  check_error(c.Get("/api/tables/1/export?format=xls"), 400, "json, csv, m, h or fmu");
  check_error(c.Get("/api/runs/1/samples?points=abc"), 400, "points");
  check_error(c.Get("/api/runs/1/samples?points=0"), 400, "points");
  check_error(c.Get("/api/runs/1/samples?t0=5&t1=1"), 400, "t1");
  check_error(c.Post("/api/campaigns/1/abort"), 409, "completed");
  // Too large a body: refused before it is read into memory.
  check_error(c.Post("/api/evaluate", std::string(live.config.http.max_body_bytes + 10, ' '), "application/json"), 413, "max_body_bytes");
  // Another site's page in a browser on this machine cannot drive the rig.
  httplib::Headers cross{{"Origin", "http://evil.example"}};
  check_error(c.Post("/api/campaigns", cross, json{{"plan", test::fot_plan(2)}}.dump(), "application/json"), 403, "evil.example");
  // The daemon is still well after all of it.
  CHECK(c.Get("/api/status")->status == 200);
}

TEST_CASE("the token rule: changes need the token, reads do not; beyond loopback it is required") {
  test::LiveDaemon live([](daemon::DaemonConfig& c) { c.http.token = "0123456789abcdef-secret"; });
  auto c = live.client();
  check_error(post(c, "/api/campaigns", {{"plan", test::fot_plan(2)}}), 401, "token");
  c.set_bearer_token_auth("wrong-token-wrong-token");
  check_error(post(c, "/api/campaigns", {{"plan", test::fot_plan(2)}}), 401, "does not match");
  CHECK(c.Get("/api/campaigns")->status == 200);
  c.set_bearer_token_auth("0123456789abcdef-secret");
  CHECK(post(c, "/api/campaigns", {{"plan", test::fot_plan(2)}})->status == 201);
  httplib::Client plain("127.0.0.1", live.http->port());
  CHECK(plain.Get("/api/status")->status == 200);
  check_error(plain.Post("/api/campaigns/1/abort"), 401, "token");

  daemon::HttpConfig open;
  open.bind = "0.0.0.0";
  CHECK_THROWS_WITH_AS(daemon::check_http_security(open, nullptr), doctest::Contains("token"), daemon::ConfigError);
  open.token = "short";
  CHECK_THROWS_AS(daemon::check_http_security(open, nullptr), daemon::ConfigError);
  open.token.clear();
  daemon::check_http_security(open, "a-token-from-the-environment");
  CHECK(open.token == "a-token-from-the-environment");
  // The daemon itself refuses to start so.
  const std::string cmd = std::string("env -u HYSTLAB_TOKEN '") + HYSTLABD + "' --bind 0.0.0.0 --db " + (live.dir.path / "x.db").string() + " > " +
                          (live.dir.path / "refused.log").string() + " 2>&1";
  const int rc = std::system(cmd.c_str());
  CHECK(WEXITSTATUS(rc) == 2);
}

TEST_CASE("static files: the page and the plotting library, and nothing outside the web root") {
  test::LiveDaemon live;
  auto c = live.client();
  auto r = c.Get("/");
  REQUIRE(r);
  CHECK(r->status == 200);
  CHECK(r->body.find("<title>hystlab</title>") != std::string::npos);
  CHECK(r->get_header_value("Content-Security-Policy").find("default-src 'self'") != std::string::npos);
  CHECK(r->get_header_value("Content-Type") == "text/html");
  // The page's modules typed as JavaScript (a browser refuses a module of another type, and
  // nosniff forbids it to guess); a path no file has, JSON's 404 (page_route.cpp).
  r = c.Get("/app.js");
  REQUIRE(r);
  CHECK(r->status == 200);
  CHECK(r->get_header_value("Content-Type") == "text/javascript");
  CHECK(c.Get("/style.css")->get_header_value("Content-Type") == "text/css");
  const auto head = c.Head("/");  // HEAD and ranges as the mount point gave them
  REQUIRE(head);
  CHECK(head->status == 200);
  CHECK(head->body.empty());
  const auto part = c.Get("/app.js", httplib::Headers{{"Range", "bytes=0-9"}});
  REQUIRE(part);
  CHECK(part->status == 206);
  CHECK(part->body.size() == 10);
  for (const std::string missing : {"/nope.js", "/api/nope", "/.hidden", "/a/b/"}) {
    CAPTURE(missing);
    r = c.Get(missing);
    REQUIRE(r);
    CHECK(r->status == 404);
    CHECK(r->body.find("no such resource") != std::string::npos);
  }
  r = c.Get("/vendor/uplot/uPlot.iife.min.js");
  REQUIRE(r);
  CHECK(r->status == 200);  // installed by the set-up command (npm ci in web/)
  const int port = live.http->port();
  for (const std::string path :
       {"/../../../../etc/passwd", "/vendor/uplot/../../package.json", "/%2e%2e/%2e%2e/%2e%2e/etc/passwd", "/..%2f..%2f..%2fetc%2fpasswd",
        "/vendor/uplot/..%2f..%2fpackage.json", "/static/../CMakeLists.txt", "//etc/passwd", "/....//....//etc/passwd"}) {
    const std::string answer = test::raw_request(port, "GET " + path + " HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
    CAPTURE(path);
    CAPTURE(answer.substr(0, 200));
    CHECK(answer.rfind("HTTP/1.1 200", 0) != 0);
    CHECK(answer.find("root:") == std::string::npos);
    CHECK(answer.find("\"devDependencies\"") == std::string::npos);
    CHECK(answer.find("add_library") == std::string::npos);
  }
  // A garbage request line is refused, and the server carries on.
  CHECK(test::raw_request(port, "BLAH\r\n\r\n").rfind("HTTP/1.1 400", 0) == 0);
  CHECK(c.Get("/api/status")->status == 200);
}

TEST_CASE("/metrics in Prometheus text format") {
  test::LiveDaemon live;
  auto c = live.client();
  REQUIRE(live.wait_json(
      "/api/rigs", [](const json& j) { return !j[0]["sample"].is_null(); }, 20));
  auto r = c.Get("/metrics");
  REQUIRE(r);
  CHECK(r->status == 200);
  CHECK(r->get_header_value("Content-Type").find("text/plain") == 0);
  for (const char* name : {"hystlab_samples_acquired_total{rig=\"sim frame\"}", "hystlab_samples_written_total", "hystlab_writer_queue_depth",
                           "hystlab_missed_deadlines_total{rig=\"sim frame\"}", "hystlab_rig_reads_total{rig=\"sim frame\"}",
                           "hystlab_rig_transaction_seconds_bucket{rig=\"sim frame\",le=\"+Inf\"}", "hystlab_sse_clients 0",
                           "hystlab_campaigns{state=\"running\"} 0", "# TYPE hystlab_rig_transaction_seconds histogram"}) {
    CAPTURE(name);
    CHECK(r->body.find(name) != std::string::npos);
  }
  // Each family's samples follow its own # TYPE line: no family is split.
  std::istringstream in(r->body);
  std::string current, line;
  std::set<std::string> seen;
  for (; std::getline(in, line);) {
    if (line.rfind("# TYPE ", 0) == 0) {
      current = line.substr(7, line.find(' ', 7) - 7);
      CHECK(seen.insert(current).second);
    } else if (line[0] != '#') {
      CAPTURE(line);
      CHECK(line.rfind(current, 0) == 0);
    }
  }
}
