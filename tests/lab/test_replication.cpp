// Replication of a daemon's SQLite store into a real PostgreSQL server of the test's own
// (tests/support/postgres_server.hpp): every row once, with the same values to the bit, through
// outages, cut-off batches and restarts; clear errors for a wrong password, no server, a newer
// schema.
#include <doctest/doctest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <thread>

#include "../support/postgres_server.hpp"
#include "hystlab/db/lab_reads.hpp"
#include "hystlab/db/pg_reads.hpp"
#include "hystlab/db/replicator.hpp"
#include "hystlab/db/store.hpp"
#include "lab_checksum.hpp"

using namespace hystlab;
using lab_test::Checksum;
using lab_test::lite_count;
using lab_test::lite_samples;
using lab_test::pg_count;
using lab_test::pg_samples;
using test_support::PostgresServer;
using test_support::TempDir;

namespace {
std::string iso(int k) { return "2026-11-28T01:00:" + std::string(k < 10 ? "0" : "") + std::to_string(k) + ".000Z"; }

// A load frame's campaign in a store: a rig, a campaign running, a run with n samples of values
// no text round-trip could hide (random doubles of every magnitude, a NaN-free set), events.
struct Filled {
  std::int64_t rig = 0, campaign = 0, run = 0, seq = 0;
};
void add_samples(db::Store& s, Filled& f, int n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<db::SampleRow> rows;
  for (int k = 0; k < n; ++k, ++f.seq)
    rows.push_back({f.run, f.seq, static_cast<double>(f.seq) * 1e-3, u(rng) * 1e-7, u(rng) * 3, u(rng) * 1e5, static_cast<std::int64_t>(f.seq % 7)});
  s.insert_samples(rows);
}
Filled fill(db::Store& s, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Filled f;
  f.rig = s.upsert_rig("frame A", R"({"transport":"modbus-tcp"})", iso(0));
  f.campaign = s.create_campaign(f.rig, domain::CampaignKind::fot, R"({"kind":"fot","specimen":"SMA spring 7","n":12})", iso(1));
  s.transition(f.campaign, domain::CampaignState::arming, "operator", iso(2));
  s.transition(f.campaign, domain::CampaignState::running, "armed", iso(3));
  f.run = s.add_run(f.campaign, iso(3), 1.8e9, 12.5);
  add_samples(s, f, n, rng);
  s.add_fot_node(f.run, 0.5, 0.25, 10.0, 5.0, 1.5);
  return f;
}

db::Replicator replicator(const PostgresServer& pg, const std::string& path, const std::string& daemon, std::size_t batch = 5000) {
  return db::Replicator(path, {"materials-lab", daemon, "test", ""}, pg.url(), PostgresServer::kPassword, batch);
}
int until_caught_up(db::Replicator& r) {
  for (int k = 0; k < 100; ++k)
    if (r.pass(4).caught_up) return k + 1;
  FAIL("not caught up in 100 passes");
  return 0;
}
}  // namespace

TEST_CASE("replication: every row once, samples equal to the bit, changes followed until final; two daemons apart") {
  PostgresServer server;
  TempDir dir("replica");
  db::Store a((dir / "a.db").string()), b((dir / "b.db").string());
  Filled fa = fill(a, 23456, 1), fb = fill(b, 3000, 2);
  CHECK(fa.run == fb.run);  // the same local ids in both files: kept apart by daemon_id
  auto ra = replicator(server, (dir / "a.db").string(), "frame-pc-1");
  auto rb = replicator(server, (dir / "b.db").string(), "frame-pc-2");
  CHECK(until_caught_up(ra) >= 2);  // 23456 samples in batches of 5000, 4 to a pass
  until_caught_up(rb);
  CHECK(ra.backlog_samples() == 0);
  CHECK(ra.daemon_id() != rb.daemon_id());

  db::PgConnection pg(server.url(), PostgresServer::kPassword);
  for (auto [store, rep] : {std::pair{&a, &ra}, std::pair{&b, &rb}}) {
    const Checksum lite = lite_samples(store->database()), copy = pg_samples(pg, rep->daemon_id());
    CHECK(copy.rows == lite.rows);
    CHECK(copy.h == lite.h);
    for (const char* t : {"rigs", "campaigns", "runs", "events", "fot_nodes"}) {
      CAPTURE(t);
      CHECK(pg_count(pg, t, rep->daemon_id()) == lite_count(store->database(), t));
    }
  }
  CHECK(pg.query("SELECT specimen FROM hystlab.lab_campaigns WHERE daemon = 'frame-pc-1'").text(0, 0) == "SMA spring 7");

  // The campaign goes on and ends: new samples, a sweep point whose prediction comes later, the
  // run ended, the campaign completed, a table stored; all of it followed.
  std::mt19937_64 rng(3);
  add_samples(a, fa, 777, rng);
  const auto point = a.add_transmissibility(fa.run, 20.0, 0.05, 0.1, 2.0, -0.3);
  ra.pass();
  a.set_prediction(point, 2.1, -0.31);
  a.end_run(fa.run, domain::CampaignState::completed, iso(40));
  a.add_table(fa.campaign, fa.run, "fot", 12, 0, 1, iso(41), R"({"rms_N":0.2})", R"({"n":12})");
  a.transition(fa.campaign, domain::CampaignState::completed, "done", iso(42));
  until_caught_up(ra);
  const std::string id = std::to_string(ra.daemon_id());
  CHECK(pg.query("SELECT predicted_ratio FROM hystlab.transmissibility WHERE daemon_id = $1", {id.c_str()}).text(0, 0) == "2.1");
  CHECK_FALSE(pg.query("SELECT ended_at FROM hystlab.runs WHERE daemon_id = $1", {id.c_str()}).is_null(0, 0));
  CHECK(pg.query("SELECT state FROM hystlab.campaigns WHERE daemon_id = $1", {id.c_str()}).text(0, 0) == "completed");
  CHECK(pg_count(pg, "tables", ra.daemon_id()) == 1);
  CHECK(pg_samples(pg, ra.daemon_id()).h == lite_samples(a.database()).h);
  CHECK(pg_count(pg, "events", ra.daemon_id()) == lite_count(a.database(), "events"));
  // Nothing left to do: a pass copies no sample and no appended row.
  CHECK(ra.pass().samples == 0);
  CHECK(pg_count(pg, "samples", ra.daemon_id()) == 23456 + 777);
  CHECK(pg_count(pg, "samples", rb.daemon_id()) == 3000);

  // What the lab view and `hystlab lab` read: both daemons, their rigs, campaigns and tables by
  // name, a run's overview with every peak kept, every sample back in order.
  db::LabReads lab(pg);
  REQUIRE(lab.daemons("materials-lab").size() == 2);
  CHECK(lab.rigs().size() == 2);
  const auto campaigns = lab.campaigns({"materials-lab", "frame-pc-1", "SMA spring 7", "", 10});
  REQUIRE(campaigns.size() == 1);
  CHECK(campaigns[0].state == "completed");
  CHECK(campaigns[0].rig == "frame A");
  CHECK(lab.campaigns({"", "", "no such specimen", "", 10}).empty());
  const auto one = lab.campaign("frame-pc-1", fa.campaign);
  REQUIRE(one);
  CHECK(one->plan.find("SMA spring 7") != std::string::npos);
  const auto runs = lab.runs(one->daemon_id, fa.campaign);
  REQUIRE(runs.size() == 1);
  CHECK(runs[0].samples == 23456 + 777);
  CHECK_FALSE(runs[0].shaker);
  CHECK(lab.events(one->daemon_id, fa.campaign).size() == static_cast<std::size_t>(lite_count(a.database(), "events")));
  const auto tables = lab.tables({"materials-lab", "", "SMA spring 7", "", 10});
  REQUIRE(tables.size() == 1);
  CHECK(tables[0].accuracy.find("rms_N") != std::string::npos);
  CHECK(lab.table_document("frame-pc-1", tables[0].id).has_value());
  const db::LabOverview o = lab.overview(one->daemon_id, fa.run, false, 100);
  REQUIRE(o.columns.size() == 4);
  REQUIRE(o.max[3].size() >= 90);
  double peak = -1e300, lite_peak = -1e300;
  for (const double v : o.max[3]) peak = std::max(peak, v);
  db::Statement st(a.database(), "SELECT max(force) FROM samples");
  st.step();
  lite_peak = st.column_double(0);
  CHECK(peak == lite_peak);
  std::int64_t n = 0, last = -1;
  bool ordered = true;
  db::PgReads(pg, one->daemon_id).for_each_sample(fa.run, 0, std::numeric_limits<std::int64_t>::max(), [&](const db::SampleRow& row) {
    ordered = ordered && row.seq == last + 1;
    last = row.seq, ++n;
  });
  CHECK(n == 23456 + 777);
  CHECK(ordered);
  // docs/LAB.md's example query, as written there.
  const db::PgResult held =
      pg.query("SELECT daemon, table_id, method, n, held_out_rms_n FROM hystlab.lab_tables WHERE specimen LIKE 'SMA spring%' ORDER BY 5;");
  CHECK(held.rows() == 1);
}

TEST_CASE("replication: PostgreSQL stopped mid-campaign and started again, or a batch cut off: caught up, nothing lost or doubled") {
  PostgresServer server;
  TempDir dir("replica");
  const std::string path = (dir / "a.db").string();
  db::Store a(path);
  Filled f = fill(a, 5000, 4);
  std::mt19937_64 rng(5);
  auto r = replicator(server, path, "frame-pc-1", 1000);
  until_caught_up(r);
  server.stop();
  add_samples(a, f, 4321, rng);  // the campaign goes on while the lab database is down
  a.end_run(f.run, domain::CampaignState::completed, iso(50));
  a.transition(f.campaign, domain::CampaignState::completed, "done", iso(51));
  CHECK_THROWS_AS(r.pass(), db::PgError);
  CHECK_FALSE(r.connected());
  server.start();
  until_caught_up(r);
  db::PgConnection pg(server.url(), PostgresServer::kPassword);
  CHECK(pg_samples(pg, r.daemon_id()).rows == 9321);
  CHECK(pg_samples(pg, r.daemon_id()).h == lite_samples(a.database()).h);
  const std::string id = std::to_string(r.daemon_id());
  CHECK(pg.query("SELECT state FROM hystlab.campaigns WHERE daemon_id = $1", {id.c_str()}).text(0, 0) == "completed");

  // The replicator's own connection killed in the middle of its passes (as a daemon killed
  // mid-COPY is, from the server's side): the batch in flight is rolled back with its mark, and
  // the next session copies it whole, once.
  add_samples(a, f, 60000, rng);
  {
    auto busy = replicator(server, path, "frame-pc-1", 500);
    busy.connect();
    std::atomic<bool> done{false};
    std::thread killer([&] {
      db::PgConnection admin(server.url(), PostgresServer::kPassword);
      while (!done)
        if (admin
                .query("SELECT pg_terminate_backend(pid) FROM pg_stat_activity WHERE application_name = 'hystlabd frame-pc-1' AND state = 'active' AND pid <> "
                       "pg_backend_pid()")
                .rows() > 0)
          return;
    });
    bool cut = false;
    try {
      for (int k = 0; k < 200 && !busy.pass(4).caught_up; ++k) {
      }
    } catch (const db::PgError&) {
      cut = true;
    }
    done = true;
    killer.join();
    CHECK(cut);  // the kill landed while it was copying
  }
  auto resumed = replicator(server, path, "frame-pc-1", 1000);
  until_caught_up(resumed);
  CHECK(pg_samples(pg, r.daemon_id()).rows == 9321 + 60000);
  CHECK(pg_samples(pg, r.daemon_id()).h == lite_samples(a.database()).h);

  // A batch cut off before its commit (the daemon killed mid-COPY): neither its rows nor its mark
  // are there, and a new replicator (the daemon restarted) copies it whole, once.
  add_samples(a, f, 2500, rng);
  {
    db::PgConnection cut(server.url(), PostgresServer::kPassword);
    cut.exec("BEGIN");
    const std::string next = std::to_string(9321 + 60000);  // the next sample's seq
    cut.copy_in("COPY hystlab.samples(daemon_id, run_id, seq, t) FROM STDIN", id + "\t" + std::to_string(f.run) + "\t" + next + "\t9.321\n");
    cut.exec("INSERT INTO hystlab.marks VALUES(" + id + ", 'samples', " + std::to_string(f.run) + ", " + next +
             ") ON CONFLICT (daemon_id, tbl, key) DO UPDATE SET mark = " + next);
  }  // the connection closes without COMMIT, as a killed process's does
  auto again = replicator(server, path, "frame-pc-1", 1000);
  until_caught_up(again);
  CHECK(again.daemon_id() == r.daemon_id());
  CHECK(pg_samples(pg, r.daemon_id()).rows == 9321 + 60000 + 2500);
  CHECK(pg_samples(pg, r.daemon_id()).h == lite_samples(a.database()).h);
}

TEST_CASE("replication: a wrong password, no server, a newer schema: one clear error each, nothing written") {
  PostgresServer server;
  TempDir dir("replica");
  const std::string path = (dir / "a.db").string();
  db::Store a(path);
  fill(a, 10, 6);
  db::Replicator wrong(path, {"materials-lab", "frame-pc-1", "test", ""}, server.url(), "not-the-password");
  try {
    wrong.connect();
    FAIL("connected with a wrong password");
  } catch (const db::PgError& e) {
    CHECK(std::string(e.what()).find("password authentication failed for user \"hystlab\"") != std::string::npos);
    CHECK(std::string(e.what()).find("not-the-password") == std::string::npos);
    CHECK(e.sqlstate == "28P01");
  }
  db::Replicator nobody(path, {"materials-lab", "frame-pc-1", "test", ""},
                        "postgresql://hystlab@127.0.0.1:" + std::to_string(test_support::free_port()) + "/lab", PostgresServer::kPassword);
  try {
    nobody.connect();
    FAIL("connected to no server");
  } catch (const db::PgError& e) {
    CHECK(std::string(e.what()).find("cannot connect") != std::string::npos);
    CHECK(std::string(e.what()).find("Connection refused") != std::string::npos);
  }
  db::PgConnection pg(server.url(), PostgresServer::kPassword);
  db::pg_migrate(pg);
  pg.exec("INSERT INTO hystlab.schema_version(version) VALUES(99)");
  auto newer = replicator(server, path, "frame-pc-1");
  try {
    newer.connect();
    FAIL("replicated into a newer schema");
  } catch (const db::PgSchemaError& e) {
    CHECK(std::string(e.what()).find("schema version 99, newer than this hystlabd's (1)") != std::string::npos);
  }
  CHECK(pg.query("SELECT count(*) FROM hystlab.daemons").integer(0, 0) == 0);
}

TEST_CASE("replication: a run id SQLite gives again after removing a run is copied as the new run; a second file under one name is refused") {
  PostgresServer server;
  TempDir dir("replica");
  const std::string path = (dir / "a.db").string();
  db::Store a(path);
  Filled f = fill(a, 100, 7);
  const auto [run, validation] = a.add_runs(f.campaign, iso(10), 1.8e9, 20.0, true);
  auto r = replicator(server, path, "frame-pc-1");
  until_caught_up(r);
  // The validation run never started: the campaign's end removes it (store_lifecycle.cpp), and
  // SQLite gives its id, the newest, to the next run.
  a.database().exec("DELETE FROM runs WHERE id = " + std::to_string(validation));
  until_caught_up(r);
  const auto c2 = a.create_campaign(f.rig, domain::CampaignKind::fot, R"({"kind":"fot","specimen":"SMA spring 9"})", iso(20));
  const std::int64_t again = a.add_run(c2, iso(21), 1.8e9, 30.0);
  REQUIRE(again == validation);
  Filled g{f.rig, c2, again, 0};
  std::mt19937_64 rng(8);
  add_samples(a, g, 500, rng);
  until_caught_up(r);
  db::PgConnection pg(server.url(), PostgresServer::kPassword);
  const std::string id = std::to_string(r.daemon_id()), run_id = std::to_string(again);
  const db::PgResult row = pg.query("SELECT campaign_id FROM hystlab.runs WHERE daemon_id = $1 AND id = $2", {id.c_str(), run_id.c_str()});
  REQUIRE(row.rows() == 1);
  CHECK(row.integer(0, 0) == c2);
  CHECK(pg_samples(pg, r.daemon_id()).h == lite_samples(a.database()).h);
  CHECK(pg_count(pg, "runs", r.daemon_id()) == lite_count(a.database(), "runs"));
  (void)run;

  // Another SQLite file under the same lab.daemon: its ids would start again under the first
  // file's marks; refused, naming the field, nothing written.
  db::Store b((dir / "b.db").string());
  fill(b, 10, 9);
  auto other = replicator(server, (dir / "b.db").string(), "frame-pc-1");
  try {
    other.connect();
    FAIL("a second file replicated under one daemon's name");
  } catch (const db::PgError& e) {
    CHECK(std::string(e.what()).find("lab.daemon 'frame-pc-1' of lab 'materials-lab' is replicated from another SQLite file") != std::string::npos);
  }
  CHECK(pg_count(pg, "campaigns", r.daemon_id()) == 2);
}
