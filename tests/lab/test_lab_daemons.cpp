// Two hystlabd processes with simulated load frames replicate into one PostgreSQL of the test's
// own: the lab database is stopped for 30 s mid-campaign (the daemons keep acquiring, the
// campaigns end while it is down), one daemon is killed with SIGKILL mid-batch while catching up and
// restarted; in the end every sample of both is there once, equal to the bit to SQLite's. A
// wrong password is one clear error in /api/status and the daemon acquires anyway.
#include <doctest/doctest.h>
#include <httplib.h>
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>

#include "../support/daemon_process.hpp"
#include "../support/postgres_server.hpp"
#include "hystlab/db/pg.hpp"
#include "hystlab/db/sqlite.hpp"
#include "lab_checksum.hpp"
#include "lab_daemon.hpp"

using namespace hystlab;
using nlohmann::json;
using test_support::PostgresServer;
using test_support::TempDir;

namespace {
using lab_test::LabDaemon;
using test_support::wait_until;

std::string campaign_state(const std::string& db_path, std::int64_t id) {
  db::Database d(db_path, false);
  db::Statement st(d, "SELECT state FROM campaigns WHERE id = ?");
  st.bind(1, id);
  return st.step() ? st.column_text(0) : "";
}
int daemon_id(db::PgConnection& pg, const std::string& name) {
  const db::PgResult r = pg.query("SELECT id FROM hystlab.daemons WHERE name = $1", {name.c_str()});
  return r.rows() == 1 ? static_cast<int>(r.integer(0, 0)) : 0;
}
// Both sides hold the same samples, campaigns and events.
bool same(db::PgConnection& pg, const LabDaemon& d) {
  const int id = daemon_id(pg, d.name());
  if (id == 0) return false;
  db::Database lite(d.db(), false);
  for (const char* t : {"campaigns", "runs", "events", "fot_nodes", "tables"})
    if (lab_test::lite_count(lite, t) != lab_test::pg_count(pg, t, id)) return false;
  const lab_test::Checksum a = lab_test::lite_samples(lite), b = lab_test::pg_samples(pg, id);
  return a.rows > 0 && a.rows == b.rows && a.h == b.h;
}
}  // namespace

TEST_CASE("lab: two daemons replicate into one database through a 30 s outage and a kill -9; a wrong password is one clear error") {
  PostgresServer server;
  setenv("HYSTLAB_TEST_PG_PASSWORD", PostgresServer::kPassword, 1);
  setenv("HYSTLAB_TEST_PG_WRONG", "not-the-password", 1);
  LabDaemon a(server, {.name = "frame-pc-1"}), b(server, {.name = "frame-pc-2"});
  const std::int64_t ca = a.submit(), cb = b.submit();
  REQUIRE(wait_until([&] { return a.get("/api/status")["lab"]["postgresql"]["samples"].get<std::int64_t>() > 1000; }, 60));
  CHECK(a.get("/api/status")["lab"]["postgresql"]["connected"] == true);

  // The lab database goes away for 30 s mid-campaign: the daemons keep acquiring, and say why
  // nothing is replicated.
  server.stop();
  const auto acquired = [](LabDaemon& d) { return d.get("/api/rigs")[0]["samples"].get<std::int64_t>(); };
  const std::int64_t before = acquired(a);
  std::this_thread::sleep_for(std::chrono::seconds(30));
  const json down = a.get("/api/status")["lab"]["postgresql"];
  CHECK(down["connected"] == false);
  CHECK(down["error"].get<std::string>().find("PostgreSQL") != std::string::npos);
  CHECK(down["lag_s"].get<double>() > 20);
  CHECK(acquired(a) > before);  // acquisition went on
  server.start();

  // Killed mid-batch while catching up (a backlog of about 3·10^5 samples, batches of 20,000):
  // when PostgreSQL shows its session inside a transaction that has begun a COPY of samples
  // (pg_stat_activity; the replicator names its session), the daemon dies. Restarted on the same
  // files, it resumes from PostgreSQL's marks: the batch that died with it is copied again, once.
  {
    db::PgConnection watch(server.url(), PostgresServer::kPassword);
    std::string xid;  // the batch's transaction, streaming its COPY
    const auto copying = [&] {
      const db::PgResult r = watch.query(
          "SELECT backend_xid::text FROM pg_stat_activity WHERE application_name = 'hystlabd frame-pc-1' AND state = 'active' "
          "AND backend_xid IS NOT NULL AND query LIKE 'COPY hystlab.samples%'");
      if (r.rows() == 0) return false;
      xid = r.text(0, 0);
      return true;
    };
    REQUIRE(wait_until(copying, 60, std::chrono::milliseconds(1)));
    a.stop(SIGKILL);
    // The server notices the client gone and ends its session: the batch's transaction aborted
    // (a fresh cluster: its 32-bit xid is its xid8), its rows and its mark with it.
    REQUIRE(
        wait_until([&] { return watch.query("SELECT count(*) FROM pg_stat_activity WHERE application_name = 'hystlabd frame-pc-1'").integer(0, 0) == 0; }, 30));
    CHECK(watch.query("SELECT pg_xact_status($1::xid8)", {xid.c_str()}).text(0, 0) == "aborted");
  }
  a.start();
  db::PgConnection pg(server.url(), PostgresServer::kPassword);
  REQUIRE(wait_until([&] { return campaign_state(b.db(), cb) == "completed"; }, 120));
  CHECK(wait_until([&] { return same(pg, b); }, 30));
  // The dashboard's views: the run's data quality as the daemon measured it, the tables' held-out score.
  const db::PgResult q = pg.query("SELECT rate_hz, missed_deadlines, samples FROM hystlab.run_quality WHERE daemon = 'frame-pc-2' AND role = 'campaign'");
  REQUIRE(q.rows() == 1);
  // The rate the daemon measured, as its own API gives it: a figure of the machine's load that
  // minute (25 samples a wall second asked), so compared with the daemon's, not with a bound.
  double measured = -1;
  const json campaign_b = b.get("/api/campaigns/" + std::to_string(cb));
  for (const json& r : campaign_b["runs"])
    if (r["role"] == "campaign") measured = r["quality"]["rate_hz"].get<double>();
  CHECK(measured > 0);
  CHECK(std::strtod(q.text(0, 0).c_str(), nullptr) == doctest::Approx(measured).epsilon(1e-6));
  CHECK_FALSE(q.is_null(0, 1));
  CHECK(q.integer(0, 2) > 1000);
  const db::PgResult t = pg.query("SELECT held_out_rms_n FROM hystlab.lab_tables WHERE daemon = 'frame-pc-2' AND held_out_rms_n IS NOT NULL");
  CHECK(t.rows() >= 1);
  // Daemon a's campaign was interrupted by the kill: it is final there, and so here.
  CHECK(wait_until([&] { return same(pg, a); }, 30));
  const std::string ida = std::to_string(daemon_id(pg, "frame-pc-1"));
  CHECK(wait_until(
      [&] {
        const db::PgResult r = pg.query("SELECT state FROM hystlab.campaigns WHERE daemon_id = $1 AND id = $2", {ida.c_str(), std::to_string(ca).c_str()});
        return r.rows() == 1 && r.text(0, 0) == campaign_state(a.db(), ca);
      },
      30));
  CHECK(a.get("/api/status")["lab"]["postgresql"]["backlog_samples"] == 0);
  const std::string metrics = a.text("/metrics");
  CHECK(metrics.find("hystlab_replication_backlog_samples 0\n") != std::string::npos);
  CHECK(metrics.find("hystlab_replication_connected 1\n") != std::string::npos);

  // A wrong password: one clear error, and the daemon acquires anyway.
  LabDaemon wrong(server, {.name = "frame-pc-3", .password_env = "HYSTLAB_TEST_PG_WRONG"});
  wrong.submit();
  REQUIRE(wait_until([&] { return !wrong.get("/api/status")["lab"]["postgresql"]["error"].is_null(); }, 30));
  const std::string why = wrong.get("/api/status")["lab"]["postgresql"]["error"];
  CHECK(why.find("password authentication failed for user \"hystlab\"") != std::string::npos);
  CHECK(why.find("not-the-password") == std::string::npos);
  CHECK(wait_until([&] { return acquired(wrong) > 500; }, 30));
  CHECK(daemon_id(pg, "frame-pc-3") == 0);

  // The lab view over it (a lab section and no rigs): both daemons and their campaigns, a run's
  // overview, read-only.
  LabDaemon view(server, {.name = "", .view = true});
  const json lab = view.get("/api/lab");
  CHECK(lab["lab"] == "materials-lab");
  REQUIRE(lab["daemons"].size() == 2);
  CHECK(lab["daemons"][0]["url"] == "http://127.0.0.1:" + std::to_string(a.port()) + "/");
  CHECK(lab["rigs"].size() == 2);
  const json campaigns = view.get("/api/lab/campaigns");
  REQUIRE(campaigns.size() == 2);
  const json one = view.get("/api/lab/campaigns/frame-pc-2/" + std::to_string(cb));
  CHECK(one["state"] == "completed");
  REQUIRE(one["runs"].size() >= 1);
  const json o = view.get("/api/lab/runs/frame-pc-2/" + std::to_string(one["runs"][0]["id"].get<std::int64_t>()) + "/overview?buckets=100");
  CHECK(o["buckets"].get<int>() >= 50);
  CHECK(o["max"]["force"].size() == o["buckets"].get<std::size_t>());
  int status = 0;
  (void)view.text("/api/lab/campaigns/frame-pc-9/1", &status);
  CHECK(status == 404);
  (void)view.text("/api/lab/campaigns?limit=0", &status);
  CHECK(status == 400);
  httplib::Client c("127.0.0.1", view.port());
  const auto post = c.Post("/api/campaigns", R"({"plan": {}})", "application/json");
  REQUIRE(post);
  CHECK(post->status == 405);
  CHECK(post->body.find("read-only") != std::string::npos);
  CHECK(view.get("/api/status")["mode"] == "lab view");

  // A rig daemon's read endpoints, answered from the lab database at /daemons/NAME/api/...: the
  // same JSON as the daemon's own (its campaign completed and caught up above).
  const std::string c1 = std::to_string(cb);
  std::vector<std::string> paths = {"/api/campaigns", "/api/campaigns?state=completed", "/api/tables"};
  for (const char* tail : {"", "/events", "/nodes", "/loops", "/runs", "/sweep", "/transmissibility"}) paths.push_back("/api/campaigns/" + c1 + tail);
  const json runs = b.get("/api/campaigns/" + c1 + "/runs");
  REQUIRE(runs.size() >= 2);  // its run and its validation run
  for (const json& r : runs)
    for (const char* tail : {"", "/samples?points=300", "/samples?points=40&t0=1.5&t1=9.25", "/loop?points=300"})
      paths.push_back("/api/runs/" + std::to_string(r["id"].get<std::int64_t>()) + tail);
  const json tables = b.get("/api/tables");
  REQUIRE(tables.size() >= 1);
  for (const json& tb : tables) {
    const std::string id = std::to_string(tb["id"].get<std::int64_t>());
    paths.push_back("/api/tables/" + id);
    paths.push_back("/api/tables/" + id + "/score?run=" + std::to_string(runs.back()["id"].get<std::int64_t>()));
    paths.push_back("/api/tables/" + id + "/export?format=json");
  }
  for (const std::string& p : paths) {
    CAPTURE(p);
    CHECK(view.get("/daemons/frame-pc-2" + p) == b.get(p));
  }
  const std::string table = std::to_string(tables[0]["id"].get<std::int64_t>());
  CHECK(view.text("/daemons/frame-pc-2/api/tables/" + table + "/export?format=csv") == b.text("/api/tables/" + table + "/export?format=csv"));
  CHECK(view.text("/daemons/frame-pc-2/api/campaigns/" + c1 + "/sweep.csv") == b.text("/api/campaigns/" + c1 + "/sweep.csv"));
  (void)view.text("/daemons/frame-pc-9/api/campaigns", &status);
  CHECK(status == 404);
  CHECK(view.text("/daemons/frame-pc-2/api/campaigns/999", &status).find("no campaign 999") != std::string::npos);
  CHECK(status == 404);
  // The rig's own page over it, read-only (the page reads its API's place from the meta).
  const std::string page = view.text("/daemons/frame-pc-2/", &status);
  CHECK(status == 200);
  CHECK(page.find(R"(<meta name="hystlab-base" content="/daemons/frame-pc-2" data-daemon="frame-pc-2">)") != std::string::npos);
  (void)view.text("/app.js", &status);
  CHECK(status == 200);
}
