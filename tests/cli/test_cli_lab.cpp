// `hystlab lab ...` and `hystlab runs export --pg` run as the real binary against a PostgreSQL
// server of the test's own (tests/support/postgres_server.hpp), filled by replicating two daemons'
// stores (db::Replicator) of the same specimen: every listing's values, the compare's ranking
// and its best, a run's CSV equal byte for byte to the export from the daemon's own file, and
// one clear error line each for what can go wrong (no server, a refused password, a URL with a
// password, an unknown daemon, campaign, run or table, a database no daemon replicates to).
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "../support/build_paths.hpp"
#include "../support/postgres_server.hpp"
#include "cli_workdir.hpp"
#include "hystlab/db/replicator.hpp"
#include "hystlab/db/sqlite.hpp"
#include "hystlab/db/store.hpp"

using namespace hystlab;
using hystlab::test::check_error;
using hystlab::test::Result;
using hystlab::test::slurp;
using hystlab::test::Workdir;
using nlohmann::json;
using test_support::PostgresServer;
using test_support::TempDir;

namespace {
constexpr const char* kSpecimen = "SMA spring 7";

std::string iso(int k) { return "2026-11-28T01:" + std::string(k < 10 ? "0" : "") + std::to_string(k) + ":05.250Z"; }

// A table's scores as the daemon writes them (models::accuracy_json, with run_finish.cpp's
// held-out block and recommendation): held_rms < 0 for a table without a validation run.
std::string accuracy(double rms, double held_rms, bool recommended) {
  const auto block = [](double r) {
    const json b{{"samples", 2000}, {"rms_N", r}, {"max_N", 4 * r}, {"rms_norm", r / 100}, {"max_norm", r / 25}};
    return json{{"overall", b}, {"ascending", b}, {"descending", b}, {"reference_range_N", 100.0}, {"loop_energy_rel_error", r / 50}};
  };
  json a = block(rms);
  if (held_rms >= 0) {
    a["held_out"] = block(held_rms);
    a["recommended"] = recommended;
    if (recommended) a["recommendation"] = "the lowest held-out RMS";
  }
  return a.dump();
}

// A load frame's run of n samples: random values of every magnitude, the extremes, a -0 and a
// NaN (which SQLite keeps as NULL), statuses of several values.
void frame_samples(db::Store& s, std::int64_t run, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<db::SampleRow> rows;
  for (int k = 0; k < n; ++k) rows.push_back({run, k, k * 1e-3, u(rng) * 1e-7, u(rng) * 3, u(rng) * 1e5, k % 7});
  rows[1].cmd = -0.0, rows[2].force = std::numeric_limits<double>::max(), rows[3].disp = 1e-300, rows[4].cmd = std::nan("");
  rows[5].force = 1.0 / 3.0;
  db::Transaction tx(s.database());
  s.insert_samples(rows);
  tx.commit();
}

void shaker_samples(db::Store& s, std::int64_t run, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<db::AnyRow> rows;
  for (int k = 0; k < n; ++k)
    rows.emplace_back(db::ShakerRow{run, k, k * 2e-4, {20 + u(rng), 0.5, u(rng) * 0.5, u(rng) * 2, u(rng) * 40, u(rng) * 300}, k % 3});
  db::Transaction tx(s.database());
  s.insert_rows(rows);
  tx.commit();
}

// A table document as hystlab writes one (models/formats.cpp): n subdivisions of [0, hi] mm.
std::string table_doc(int n, double hi) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i <= n; ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (int j = 0; j <= i; ++j) row.push_back(2.5 * (i - j) * (i - j) / n);
    rows.push_back(row);
  }
  return nlohmann::json{{"format", "hystlab-everett-table"},
                        {"version", 1},
                        {"range_mm", {0, hi}},
                        {"subdivisions", n},
                        {"force_offset_N", 0.25},
                        {"rows", rows},
                        {"provenance", {{"source", "test"}, {"method", "fot"}, {"n", n}}}}
      .dump();
}

// Daemon frame-pc-1: campaign 1 (the specimen, rig "frame A") with a run and a validation run,
// two tables (held-out RMS 0.8 and 0.5, the second recommended), a few events.
// Daemon frame-pc-2: campaign 1 (the specimen, rig "frame B"), tables with held-out RMS 0.3
// (recommended) and none (no held-out figures); campaign 2 of another specimen; campaign 3, a
// sine sweep on "shaker B" with a shaker's run.
struct Lab {
  TempDir dir{"cli-lab"};
  PostgresServer server;
  std::string a_db = (dir / "a.db").string(), b_db = (dir / "b.db").string();

  Lab() {
    {
      db::Store a(a_db);
      const auto rig = a.upsert_rig("frame A", R"({"transport":"modbus-tcp"})", iso(0));
      const auto c = a.create_campaign(rig, domain::CampaignKind::fot, R"({"kind":"fot","specimen":"SMA spring 7","n":12,"range_mm":[0,4]})", iso(1));
      a.transition(c, domain::CampaignState::arming, "operator", iso(2));
      a.transition(c, domain::CampaignState::running, "armed", iso(3));
      const auto [run, validation] = a.add_runs(c, iso(3), 1.8e9, 12.5, true);
      frame_samples(a, run, 3000, 1);
      frame_samples(a, validation, 700, 2);
      a.end_run(run, domain::CampaignState::completed, iso(10));
      a.end_run(validation, domain::CampaignState::completed, iso(11));
      a.add_raw_event(c, "note", R"({"text":"grips re-tightened"})", iso(12));
      a.add_table(c, run, "fot", 12, 0, 4, iso(13), accuracy(0.6, 0.8, false), table_doc(12, 4));
      a.add_table(c, run, "least-squares", 12, 0, 4, iso(14), accuracy(0.4, 0.5, true), table_doc(12, 4));
      a.transition(c, domain::CampaignState::completed, "done", iso(15));
    }
    {
      db::Store b(b_db);
      const auto rig = b.upsert_rig("frame B", R"({"transport":"can"})", iso(0));
      const auto c = b.create_campaign(rig, domain::CampaignKind::fot, R"({"kind":"fot","specimen":"SMA spring 7","n":10})", iso(20));
      b.transition(c, domain::CampaignState::running, "armed", iso(21));
      const auto run = b.add_run(c, iso(21), 1.8e9, 3.0);
      frame_samples(b, run, 1500, 3);
      b.add_table(c, run, "fot", 10, 0, 4, iso(22), accuracy(0.35, 0.3, true), table_doc(10, 4));
      b.add_table(c, run, "fot", 8, 0, 4, iso(23), accuracy(0.2, -1, false), table_doc(8, 4));
      b.transition(c, domain::CampaignState::completed, "done", iso(24));
      const auto other = b.create_campaign(rig, domain::CampaignKind::waveform, R"({"kind":"waveform","specimen":"rubber mount"})", iso(30));
      b.add_table(other, std::nullopt, "fot", 6, 0, 2, iso(31), accuracy(0.1, 0.05, true), table_doc(6, 2));
      const auto shaker = b.upsert_rig("shaker B", R"({"kind":"shaker"})", iso(0));
      const auto sweep = b.create_campaign(shaker, domain::CampaignKind::sine, R"({"kind":"sine","specimen":"isolator 3"})", iso(40));
      shaker_samples(b, b.add_run(sweep, iso(40), 1.8e9, 0.0), 500, 4);
    }
    for (const auto& [path, daemon] : {std::pair{a_db, "frame-pc-1"}, std::pair{b_db, "frame-pc-2"}}) {
      db::Replicator r(path, {"materials-lab", daemon, "test", ""}, server.url(), PostgresServer::kPassword);
      bool done = false;
      for (int k = 0; k < 50 && !done; ++k) done = r.pass().caught_up;
      REQUIRE(done);
    }
    dir.write("pgpass", std::string(PostgresServer::kPassword) + "\n");
  }
  // The CLI with the lab's password in $PGPASSWORD (libpq's own).
  [[nodiscard]] Result run(const Workdir& w, const std::string& args) const {
    Result rr = w.run_raw("env -u HYSTLAB_PG PGPASSWORD='" + std::string(PostgresServer::kPassword) + "' '" + HYSTLAB_CLI + "' " + args);
    std::fprintf(stderr, "$ hystlab %s\n%s%s[exit %d]\n", args.c_str(), rr.out.substr(0, 1500).c_str(), rr.err.c_str(), rr.code);
    return w.run_raw("env -u HYSTLAB_PG PGPASSWORD='" + std::string(PostgresServer::kPassword) + "' '" + HYSTLAB_CLI + "' " + args);
  }
  [[nodiscard]] std::string pg() const { return "--pg " + server.url(); }
};

// One server and its two replicated stores for every case (initdb costs seconds).
Lab& lab() {
  static const std::unique_ptr<Lab> l = std::make_unique<Lab>();
  return *l;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}
bool has(const std::string& text, const std::string& needle) { return text.find(needle) != std::string::npos; }
}  // namespace

TEST_CASE("lab campaigns: every daemon's campaigns with rig, kind, state and specimen; filters; JSON") {
  Lab& l = lab();
  Workdir w;
  Result r = l.run(w, "lab campaigns " + l.pg());
  CAPTURE(r.err);
  REQUIRE(r.code == 0);
  CAPTURE(r.out);
  const auto lines = lines_of(r.out);
  REQUIRE(lines.size() == 5);  // the heading, four campaigns
  CHECK((has(lines[0], "daemon") && has(lines[0], "specimen") && has(lines[0], "updated")));
  CHECK((has(lines[1], "frame-pc-2") && has(lines[1], "shaker B") && has(lines[1], "sine") && has(lines[1], "isolator 3")));  // the newest first
  bool a_row = false;
  for (const auto& line : lines)
    a_row = a_row || (has(line, "frame-pc-1") && has(line, "frame A") && has(line, "fot") && has(line, "completed") && has(line, kSpecimen) &&
                      has(line, "2026-11-28 01:15:05 UTC"));
  CHECK(a_row);

  r = l.run(w, "lab campaigns " + l.pg() + " --specimen '" + kSpecimen + "' --json");
  REQUIRE(r.code == 0);
  const json j = json::parse(r.out);
  REQUIRE(j.size() == 2);
  CHECK(j[0]["daemon"] == "frame-pc-2");  // updated later
  CHECK(j[1]["daemon"] == "frame-pc-1");
  CHECK(j[1]["rig"] == "frame A");
  CHECK(j[1]["id"] == 1);
  CHECK(j[1]["state"] == "completed");
  CHECK(j[1]["lab"] == "materials-lab");
  CHECK(j[1]["updated_at"] == "2026-11-28T01:15:05.25Z");

  r = l.run(w, "lab campaigns " + l.pg() + " --daemon frame-pc-2 --kind waveform --json");
  REQUIRE(r.code == 0);
  const json k = json::parse(r.out);
  REQUIRE(k.size() == 1);
  CHECK(k[0]["specimen"] == "rubber mount");
  r = l.run(w, "lab campaigns " + l.pg() + " --limit 1");
  CHECK(lines_of(r.out).size() == 2);
  r = l.run(w, "lab campaigns " + l.pg() + " --lab other-lab");
  CHECK(has(r.out, "(no campaign matches)"));
}

TEST_CASE("lab tables: each table with its own and held-out scores, the recommended marked") {
  Lab& l = lab();
  Workdir w;
  Result r = l.run(w, "lab tables " + l.pg() + " --specimen '" + std::string(kSpecimen) + "' --json");
  CAPTURE(r.err);
  REQUIRE(r.code == 0);
  const json j = json::parse(r.out);
  REQUIRE(j.size() == 4);
  std::map<std::string, json> by;
  for (const auto& t : j) by[t["daemon"].get<std::string>() + "/" + std::to_string(t["id"].get<int>())] = t;
  REQUIRE(by.size() == 4);
  CHECK(by["frame-pc-1/1"]["held_out"]["rms_N"] == 0.8);
  CHECK(by["frame-pc-1/1"]["own"]["rms_N"] == 0.6);
  CHECK(by["frame-pc-1/2"]["held_out"]["rms_N"] == 0.5);
  CHECK(by["frame-pc-1/2"]["recommended"] == true);
  CHECK(by["frame-pc-1/2"]["method"] == "least-squares");
  CHECK(by["frame-pc-2/1"]["held_out"]["max_N"] == doctest::Approx(1.2));
  CHECK(by["frame-pc-2/2"]["held_out"]["rms_N"].is_null());
  CHECK(by["frame-pc-2/2"]["n"] == 8);

  r = l.run(w, "lab tables " + l.pg());
  REQUIRE(r.code == 0);
  CAPTURE(r.out);
  CHECK(lines_of(r.out).size() == 1 + 5 + 1);  // heading, five tables, the legend of *
  CHECK(has(r.out, "rubber mount"));
  bool row = false;
  for (const auto& line : lines_of(r.out)) row = row || (has(line, "frame-pc-1") && has(line, "least-squares") && has(line, "0.5") && has(line, "*"));
  CHECK(row);
}

TEST_CASE("lab show: a campaign's plan, runs with their samples, tables and last events") {
  Lab& l = lab();
  Workdir w;
  Result r = l.run(w, "lab show frame-pc-1/1 " + l.pg());
  CAPTURE(r.err);
  REQUIRE(r.code == 0);
  CAPTURE(r.out);
  CHECK(has(r.out, "campaign frame-pc-1/1 (lab materials-lab): fot on frame A, completed"));
  CHECK(has(r.out, "specimen: SMA spring 7"));
  CHECK(has(r.out, "plan: kind=fot, n=12, range_mm=[0,4]"));
  CHECK(has(r.out, "run 1: completed, 3000 samples (load frame)"));
  CHECK(has(r.out, "run 2 (validation): completed, 700 samples (load frame)"));
  CHECK(has(r.out, "table 2: least-squares, n = 12"));
  CHECK(has(r.out, "held-out RMS 0.5 N, max 2 N (recommended)"));
  CHECK(has(r.out, "01:12:05 UTC  note"));
  CHECK(has(r.out, "grips re-tightened"));

  r = l.run(w, "lab show frame-pc-1/1 " + l.pg() + " --events 2");
  CHECK(has(r.out, "the last 2 of"));
  CHECK_FALSE(has(r.out, "01:02:05 UTC"));  // an older event: not shown

  r = l.run(w, "lab show frame-pc-2/3 " + l.pg() + " --json");
  REQUIRE(r.code == 0);
  const json j = json::parse(r.out);
  CHECK(j["kind"] == "sine");
  CHECK(j["rig"] == "shaker B");
  REQUIRE(j["runs"].size() == 1);
  CHECK(j["runs"][0]["samples"] == 500);
  CHECK(j["runs"][0]["rig_kind"] == "shaker");
  CHECK(j["plan"]["specimen"] == "isolator 3");
}

TEST_CASE("lab compare: one specimen's tables across rigs, ranked by held-out RMS, the best said") {
  Lab& l = lab();
  Workdir w;
  Result r = l.run(w, "lab compare " + l.pg() + " --specimen '" + std::string(kSpecimen) + "' --json");
  CAPTURE(r.err);
  REQUIRE(r.code == 0);
  const json j = json::parse(r.out);
  REQUIRE(j["tables"].size() == 4);
  std::vector<std::string> order;
  for (const auto& t : j["tables"]) order.push_back(t["daemon"].get<std::string>() + "/" + std::to_string(t["table"].get<int>()));
  CHECK(order == std::vector<std::string>{"frame-pc-2/1", "frame-pc-1/2", "frame-pc-1/1", "frame-pc-2/2"});
  CHECK(j["best"] == "frame-pc-2/1");
  CHECK(j["tables"][0]["rig"] == "frame B");
  CHECK(j["tables"][0]["rank"] == 1);
  CHECK(j["tables"][2]["rank"] == 3);
  CHECK(j["tables"][3]["rank"].is_null());  // no held-out figures: not ranked
  CHECK(j["tables"][1]["held_out"]["rms_pct_of_range"] == doctest::Approx(0.5));
  CHECK(j["tables"][1]["held_out"]["loop_energy_error_pct"] == doctest::Approx(1.0));
  CHECK(j["tables"][1]["held_out_samples"] == 2000);

  r = l.run(w, "lab compare " + l.pg() + " --specimen '" + std::string(kSpecimen) + "'");
  REQUIRE(r.code == 0);
  CAPTURE(r.out);
  const auto lines = lines_of(r.out);
  REQUIRE(lines.size() >= 5);
  CHECK((has(lines[1], "frame-pc-2/1") && has(lines[1], "frame B") && has(lines[1], "0.3")));
  CHECK((has(lines[2], "frame-pc-1/2") && has(lines[2], "frame A")));
  CHECK(has(r.out, "best: frame-pc-2/1 (fot, n = 10, on frame B), held-out RMS 0.3 N; next frame-pc-1/2, 0.5 N"));

  // Named tables: only those.
  r = l.run(w, "lab compare frame-pc-1/1 frame-pc-1/2 " + l.pg());
  REQUIRE(r.code == 0);
  CHECK(has(r.out, "best: frame-pc-1/2 (least-squares, n = 12, on frame A)"));
  CHECK(lines_of(r.out).size() == 1 + 2 + 2);  // heading, two tables, best, the legend of *
}

TEST_CASE("runs export --pg: a run's CSV from the lab equal byte for byte to the export from the daemon's file") {
  Lab& l = lab();
  Workdir w;
  for (const auto& [db, daemon, run] :
       {std::tuple{l.a_db, "frame-pc-1", 1}, std::tuple{l.a_db, "frame-pc-1", 2}, std::tuple{l.b_db, "frame-pc-2", 1}, std::tuple{l.b_db, "frame-pc-2", 2}}) {
    const std::string daemon_name = daemon;  // CAPTURE takes no binding (clang 14)
    const int run_id = run;
    CAPTURE(daemon_name);
    CAPTURE(run_id);
    const Result file = w.run("runs export " + std::to_string(run) + " --db " + db);
    REQUIRE(file.code == 0);
    const Result pg = l.run(w, "runs export " + std::to_string(run) + " " + l.pg() + " --daemon " + daemon);
    CAPTURE(pg.err);
    REQUIRE(pg.code == 0);
    CHECK(pg.out.size() == file.out.size());
    CHECK(pg.out == file.out);
  }
  // The shaker's columns; to a file with -o, the password from --pg-password-file.
  const Result file = w.run("runs export 2 --db " + l.b_db + " -o lite.csv");
  REQUIRE(file.code == 0);
  const Result pg = w.run_raw("env -u PGPASSWORD '" + HYSTLAB_CLI + "' runs export 2 " + l.pg() + " --daemon frame-pc-2 -o lab.csv --pg-password-file " +
                              (l.dir / "pgpass").string());
  CAPTURE(pg.err);
  REQUIRE(pg.code == 0);
  CHECK(slurp(w / "lab.csv").rfind("seq,t_s,drive_frequency_hz,", 0) == 0);
  CHECK(slurp(w / "lab.csv") == slurp(w / "lite.csv"));
  CHECK(lines_of(slurp(w / "lab.csv")).size() == 501);
}

// Two HDF5 exports hold the same: every group, dataset and attribute, values equal (NaN equal to
// NaN; text that is JSON compared as JSON: the lab database keeps JSON as jsonb, its keys in its
// own order), but the file's "created" time. Run by Debian's h5py; prints "same" or the differences.
constexpr const char* kSameH5 = R"(import sys, json, h5py, numpy as np
a, b = h5py.File(sys.argv[1], 'r'), h5py.File(sys.argv[2], 'r')
def plain(v):
    if isinstance(v, bytes): v = v.decode()
    if isinstance(v, str):
        try: return json.loads(v)
        except ValueError: return v
    return v.tolist() if isinstance(v, np.ndarray) else v
def same(x, y):
    if isinstance(x, np.ndarray) and x.dtype.kind == 'f': return x.shape == y.shape and np.array_equal(x, y, equal_nan=True)
    if isinstance(x, np.ndarray) and x.dtype.kind in 'OSU': return [plain(v) for v in x.ravel()] == [plain(v) for v in y.ravel()]
    if isinstance(x, np.ndarray): return x.dtype == y.dtype and np.array_equal(x, y)
    return plain(x) == plain(y)
diff, seen = [], 0
def attrs(name, x, y):
    for k in set(x.attrs) | set(y.attrs):
        if name == '/' and k == 'created': continue
        if k not in x.attrs or k not in y.attrs or not same(x.attrs[k], y.attrs[k]): diff.append(name + '@' + k)
def visit(name, obj):
    global seen
    seen += 1
    other = b.get(name)
    if other is None or type(other) != type(obj): return diff.append('only in the first: ' + name)
    attrs(name, obj, other)
    if isinstance(obj, h5py.Dataset) and not same(obj[()], other[()]): diff.append('values of ' + name)
a.visititems(visit)
b.visititems(lambda name, obj: None if name in a else diff.append('only in the second: ' + name))
attrs('/', a, b)
print('same' if not diff else 'differ: ' + ', '.join(diff[:20]), seen)
)";

TEST_CASE("runs export --pg --format h5: a run and a campaign as HDF5 from the lab, as from the daemon's file") {
  Lab& l = lab();
  Workdir w;
  w.write("same_h5.py", kSameH5);
  for (const auto& [what, db, daemon] :
       {std::tuple{"1", l.a_db, "frame-pc-1"}, std::tuple{"--campaign 1", l.b_db, "frame-pc-2"}, std::tuple{"2", l.b_db, "frame-pc-2"}}) {
    const std::string what_text(what), daemon_name(daemon);
    CAPTURE(what_text);
    CAPTURE(daemon_name);
    const Result file = w.run("runs export " + std::string(what) + " --format h5 -o file.h5 --db " + db);
    CAPTURE(file.err);
    REQUIRE(file.code == 0);
    const Result pg = l.run(w, "runs export " + std::string(what) + " " + l.pg() + " --daemon " + daemon + " --format h5 -o lab.h5");
    CAPTURE(pg.err);
    REQUIRE(pg.code == 0);
    // "wrote NAME: N run(s), M samples, K table(s)"
    CHECK(pg.err.substr(pg.err.find(": ")) == file.err.substr(file.err.find(": ")));
    const Result cmp = w.run_raw("/usr/bin/python3 same_h5.py file.h5 lab.h5");  // Debian's, with its h5py
    CAPTURE(cmp.err);
    CHECK(cmp.out.rfind("same ", 0) == 0);
    CHECK(cmp.out.find("same 1\n") == std::string::npos);  // more than the root compared
    CAPTURE(cmp.out);
  }
}

TEST_CASE("lab: one clear error each (no server, a refused password, a password in the URL, unknown names), exit 2") {
  Lab& l = lab();
  Workdir w;
  const std::string url = l.server.url();
  check_error(l.run(w, "lab campaigns --pg postgresql://hystlab@127.0.0.1:" + std::to_string(test_support::free_port()) + "/lab"),
              "cannot connect to the lab database");
  check_error(w.run_raw("env PGPASSWORD=wrong '" + HYSTLAB_CLI + "' lab campaigns --pg " + url), "refused the password");
  w.write("bad-pass", "wrong\n");
  check_error(w.run_raw("env -u PGPASSWORD '" + HYSTLAB_CLI + "' lab tables --pg " + url + " --pg-password-file bad-pass"), "refused the password");
  check_error(w.run_raw("env -u PGPASSWORD '" + HYSTLAB_CLI + "' lab tables --pg " + url + " --pg-password-file no-such-file"),
              "--pg-password-file: cannot read 'no-such-file'");
  check_error(
      l.run(w, "lab campaigns --pg postgresql://hystlab:" + std::string(PostgresServer::kPassword) + "@127.0.0.1:" + std::to_string(l.server.port()) + "/lab"),
      "--pg holds a password");
  check_error(l.run(w, "lab campaigns --pg 'host=127.0.0.1 password=x dbname=lab'"), "--pg holds a password");
  check_error(l.run(w, "lab campaigns"), "missing required option --pg");
  check_error(l.run(w, "lab campaigns --pg " + l.server.url("postgres")), "holds no lab");
  check_error(l.run(w, "lab show frame-pc-9/1 " + l.pg()), "no daemon 'frame-pc-9' in the lab database (it has frame-pc-1, frame-pc-2)");
  check_error(l.run(w, "lab show frame-pc-1/7 " + l.pg()), "no campaign 7 on daemon 'frame-pc-1'");
  check_error(l.run(w, "lab show frame-pc-1 " + l.pg()), "lab show must be DAEMON/ID");
  check_error(l.run(w, "lab compare frame-pc-2/9 " + l.pg()), "no table 9 on daemon 'frame-pc-2'");
  check_error(l.run(w, "lab compare " + l.pg()), "give --specimen TEXT or DAEMON/TABLE ids");
  check_error(l.run(w, "lab compare " + l.pg() + " --specimen 'no such'"), "no table of specimen 'no such'");
  check_error(l.run(w, "lab campaigns " + l.pg() + " --kind shaker"), "--kind: 'shaker' is not fot, waveform or sine");
  check_error(l.run(w, "lab frobnicate " + l.pg()), "unknown lab verb 'frobnicate'");
  check_error(l.run(w, "runs export 9 " + l.pg() + " --daemon frame-pc-1"), "there is no run 9 on daemon 'frame-pc-1' in the lab database");
  check_error(l.run(w, "runs export 1 " + l.pg() + " --daemon nobody"), "no daemon 'nobody'");
  check_error(l.run(w, "runs export 1 " + l.pg()), "give --daemon NAME");
  check_error(l.run(w, "runs export --campaign 9 " + l.pg() + " --daemon frame-pc-1 --format h5 -o x.h5"),
              "no campaign 9 on daemon 'frame-pc-1' in the lab database");
  check_error(l.run(w, "runs export --campaign 1 " + l.pg() + " --daemon frame-pc-1"), "a whole campaign is exported as HDF5 only");
  CHECK_FALSE(std::filesystem::exists(w / "x.h5"));
}

TEST_CASE("conninfo_has_password: what the CLI's --pg and the config's lab.postgresql both refuse") {
  CHECK(db::conninfo_has_password("postgresql://hystlab:secret@127.0.0.1:5432/lab"));
  CHECK(db::conninfo_has_password("postgres://u:p@host/db"));
  CHECK(db::conninfo_has_password("postgresql://u@host/db?password=p"));
  CHECK(db::conninfo_has_password("host=h dbname=lab password=p"));
  CHECK_FALSE(db::conninfo_has_password("postgresql://hystlab@127.0.0.1:5432/lab"));
  CHECK_FALSE(db::conninfo_has_password("postgresql://hystlab@[::1]:5432/lab"));
  CHECK_FALSE(db::conninfo_has_password("postgresql://host:5432/lab"));
  CHECK_FALSE(db::conninfo_has_password("host=h dbname=lab user=u"));
}
