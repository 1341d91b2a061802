// Issue 26's figures for a lab of many rigs: one daemon's SQLite replicated to the lab's
// PostgreSQL (db::Replicator), every rig live over MQTT. Prints:
//
// 1. Replication throughput of samples against a bare COPY of the same rows, same machine, same
//    run (target ratio >= 0.8). Both read the same 10^6 samples (4 runs) from the same SQLite
//    file, encode them as COPY text (daemon_id, run_id, seq, t, cmd, disp, force, status; the
//    doubles as their shortest exact text) and COPY them into hystlab.samples (16 hash partitions,
//    primary key) emptied before each measurement, in COPYs of the same number of rows.
//      bare:       the fewest lines of libpq and SQLite's C API that do it: one scan of the
//                  samples in (run_id, seq) order, each row encoded with std::to_chars into a
//                  64 KiB buffer streamed into the open COPY, one COPY (autocommitted) per batch.
//      replicator: db::Replicator::pass(10) back to back until caught up, as hystlabd's
//                  replication thread calls it: per batch, a SELECT of the run's next rows, the
//                  typed encoding of every column, BEGIN, COPY, the batch's high-water mark
//                  upserted, COMMIT (nothing lost, nothing twice); per pass, the other tables.
//    3 repetitions of each, interleaved with the order swapped each time; medians of rows/s.
//    Then where the time goes: SQLite read + encode alone, and COPY of pre-encoded text alone.
// 2. Catch-up time of a 10^6-sample backlog: the replicator's repetitions above (a fresh daemon
//    name each time: everything in SQLite is backlog), seconds and rows/s; and the bytes one
//    sample row takes in PostgreSQL (table and primary key, pg_total_relation_size).
// 3. Replication lag during a 1 kHz campaign (target p99 < 1 s) and the missed deadlines added
//    by replication and MQTT together (target 0): two hystlabd processes one after the other,
//    a simulated load frame at time scale 1 each, the same 1 kHz FOT campaign for the same time;
//    the first without a lab section (the baseline), then one with lab.postgresql and lab.mqtt,
//    replicate_every_s at its default (0.5 s; 1 s gave p99 1.07 s), and a third at
//    --replicate-every-s P when asked. lag_s (GET
//    /api/status, lab.postgresql) is the age of the newest instant at which everything SQLite
//    held was in PostgreSQL (the start of the newest pass that left nothing behind), sampled
//    every 100 ms. PostgreSQL and mosquitto stand for the lab's servers on other machines: as
//    bench_sse's clients, they run off the daemon's acquisition CPU (the last one) at the
//    lowest priority (a server of their own, started for this part).
#include <httplib.h>
#include <libpq-fe.h>
#include <pthread.h>
#include <sched.h>
#include <sqlite3.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "../support/daemon_process.hpp"
#include "../support/mosquitto_broker.hpp"
#include "../support/postgres_server.hpp"
#include "hystlab/db/pg.hpp"
#include "hystlab/db/replicator.hpp"
#include "hystlab/db/store.hpp"

namespace {
using hystlab::test_support::MosquittoBroker;
using hystlab::test_support::PostgresServer;
using hystlab::test_support::TempDir;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : (v[(v.size() - 1) / 2] + v[v.size() / 2]) / 2;
}
double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}
const char* met(bool ok) { return ok ? "met" : "NOT met"; }

struct Options {
  std::int64_t samples = 1'000'000;
  int runs = 4, reps = 3;
  std::size_t batch = 20000;                      // the replication thread's default (lab_config.hpp)
  double campaign_s = 12, replicate_every_s = 0;  // > 0: a third daemon at this period (the second: the default)
};

// A load frame's campaign: a slow triangle with noise, so every double is a full-precision one.
void fill(const std::string& path, const Options& o) {
  hystlab::db::Store s(path, false);
  const auto rig = s.upsert_rig("frame 1", R"({"transport":"modbus-tcp"})", "2026-11-28T01:00:00.000Z");
  const auto campaign = s.create_campaign(rig, hystlab::domain::CampaignKind::fot, R"({"kind":"fot"})", "2026-11-28T01:00:01.000Z");
  std::mt19937_64 rng(26);
  std::normal_distribution<double> noise(0, 1);
  std::vector<hystlab::db::SampleRow> rows;
  const std::int64_t per_run = o.samples / o.runs;
  for (int r = 0; r < o.runs; ++r) {
    const auto run = s.add_run(campaign, "2026-11-28T01:00:02.000Z", 1.8e9, 12.5);
    for (std::int64_t k = 0; k < per_run; k += 50000) {
      rows.clear();
      for (std::int64_t j = k; j < std::min(per_run, k + 50000); ++j) {
        const double t = static_cast<double>(j) * 1e-3, cmd = 2 + 2 * std::asin(std::sin(t * 0.3)) / std::numbers::pi;
        const double disp = cmd + 1e-4 * noise(rng);
        rows.push_back({run, j, t, cmd, disp, 80 * disp + 40 * std::tanh(8 * (disp - cmd)) + 0.05 * noise(rng), 5});
      }
      hystlab::db::Transaction tx(s.database());
      s.insert_samples(rows);
      tx.commit();
    }
  }
}

// ---- the bare code -------------------------------------------------------------------------
void check(PGresult* r, ExecStatusType want, PGconn* c) {
  const bool ok = PQresultStatus(r) == want;
  PQclear(r);
  if (!ok) throw std::runtime_error(std::string("bare COPY: ") + PQerrorMessage(c));
}
template <class T>
void put(std::string& b, T v) {
  char s[32];
  b.append(s, std::to_chars(s, s + sizeof s, v).ptr);
}
// One scan; every row encoded into buf; `flush(buf, end_of_batch)` called every 64 KiB and at
// every batch's end. Returns the rows.
template <class Flush>
std::int64_t scan_encode(sqlite3* lite, int daemon_id, std::size_t batch, Flush&& flush) {
  sqlite3_stmt* st = nullptr;
  sqlite3_prepare_v2(lite, "SELECT run_id, seq, t, cmd, disp, force, status FROM samples ORDER BY run_id, seq", -1, &st, nullptr);
  std::string buf;
  std::int64_t n = 0;
  std::size_t in_batch = 0;
  while (sqlite3_step(st) == SQLITE_ROW) {
    put(buf, daemon_id);
    for (int c = 0; c < 7; ++c) {
      buf += '\t';
      if (c < 2 || c == 6)
        put(buf, static_cast<std::int64_t>(sqlite3_column_int64(st, c)));
      else
        put(buf, sqlite3_column_double(st, c));
    }
    buf += '\n';
    ++n;
    if (++in_batch == batch || buf.size() >= 65536) {
      flush(buf, in_batch == batch);
      buf.clear();
      if (in_batch == batch) in_batch = 0;
    }
  }
  sqlite3_finalize(st);
  if (!buf.empty() || in_batch > 0) flush(buf, true);
  return n;
}
std::int64_t bare_copy(sqlite3* lite, PGconn* pg, int daemon_id, std::size_t batch) {
  bool open = false;
  return scan_encode(lite, daemon_id, batch, [&](const std::string& buf, bool end) {
    if (!open) check(PQexec(pg, "COPY hystlab.samples(daemon_id, run_id, seq, t, cmd, disp, force, status) FROM STDIN"), PGRES_COPY_IN, pg), open = true;
    if (PQputCopyData(pg, buf.data(), static_cast<int>(buf.size())) != 1) throw std::runtime_error(PQerrorMessage(pg));
    if (!end) return;
    PQputCopyEnd(pg, nullptr);
    check(PQgetResult(pg), PGRES_COMMAND_OK, pg);
    while (PGresult* x = PQgetResult(pg)) PQclear(x);
    open = false;
  });
}
// ---- end of the bare code ------------------------------------------------------------------

struct Lab {
  const PostgresServer& server;
  hystlab::db::PgConnection pg{server.url(), PostgresServer::kPassword};
  PGconn* raw = nullptr;
  explicit Lab(const PostgresServer& s) : server(s) {
    hystlab::db::pg_migrate(pg);
    const std::string conninfo = server.url() + "?password=" + PostgresServer::kPassword;
    raw = PQconnectdb(conninfo.c_str());
    if (PQstatus(raw) != CONNECTION_OK) throw std::runtime_error(std::string("bare connection: ") + PQerrorMessage(raw));
  }
  ~Lab() { PQfinish(raw); }
  Lab(const Lab&) = delete;
  Lab& operator=(const Lab&) = delete;
  void empty() {
    pg.exec("TRUNCATE hystlab.samples");
    pg.exec("CHECKPOINT");
  }
  std::int64_t count(int daemon_id) {
    const std::string d = std::to_string(daemon_id);
    return pg.query("SELECT count(*) FROM hystlab.samples WHERE daemon_id = $1", {d.c_str()}).integer(0, 0);
  }
};

// Keeps the calling thread (and the processes it starts) off the last CPU, at the lowest priority.
void off_acquisition_cpu() {
  (void)setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19);
  if (const long cpus = sysconf(_SC_NPROCESSORS_ONLN); cpus > 1) {
    cpu_set_t set;
    CPU_ZERO(&set);
    for (long k = 0; k + 1 < cpus; ++k) CPU_SET(static_cast<unsigned>(k), &set);
    (void)pthread_setaffinity_np(pthread_self(), sizeof set, &set);
  }
}

struct CampaignFigures {
  std::uint64_t missed = 0, late = 0, samples = 0;
  std::vector<double> lag_s;
  nlohmann::json lab;
};

// One hystlabd with a simulated load frame in real time runs a 1 kHz FOT campaign for `seconds`;
// with `lab` (a lab section), replication's lag_s is sampled every 100 ms.
CampaignFigures campaign(const nlohmann::json& lab, double seconds) {
  nlohmann::json cfg{{"rigs", nlohmann::json::array({{{"name", "sim frame"}, {"simulate", {{"time_scale", 1}}}}})}};
  if (!lab.is_null()) cfg["lab"] = lab;
  hystlab::test_support::DaemonProcess daemon(cfg.dump());
  httplib::Client c("127.0.0.1", daemon.port());
  const nlohmann::json plan{{"kind", "fot"},          {"range_mm", {0, 4}},
                            {"subdivisions", 12},     {"ramp_rate_mm_s", 0.5},
                            {"sample_rate_hz", 1000}, {"limits", {{"displacement_mm", {-0.5, 4.5}}, {"force_N", 400}, {"rate_mm_s", 20}}}};
  const auto r = c.Post("/api/campaigns", nlohmann::json{{"plan", plan}}.dump(), "application/json");
  if (!r || r->status != 201) throw std::runtime_error("cannot submit the campaign: " + (r ? r->body : std::string("no answer")));
  const auto id = nlohmann::json::parse(r->body)["id"].get<long>();
  const auto rig = [&] { return nlohmann::json::parse(c.Get("/api/rigs")->body).at(0); };
  if (!hystlab::test_support::wait_until([&] { return rig()["samples"].get<std::uint64_t>() > 0; }, 30))
    throw std::runtime_error("the campaign did not start acquiring within 30 s:\n" + daemon.log());
  CampaignFigures f;
  const auto t0 = Clock::now();
  for (int k = 1; since(t0) < seconds; ++k) {
    if (!lab.is_null()) {
      const auto s = nlohmann::json::parse(c.Get("/api/status")->body)["lab"]["postgresql"];
      if (s["connected"] == true) f.lag_s.push_back(s["lag_s"].get<double>());
    }
    std::this_thread::sleep_until(t0 + std::chrono::milliseconds(100 * k));
  }
  const auto end = rig();  // the campaign's end (then aborted): everything it missed
  f.missed = end["missed_deadlines"].get<std::uint64_t>(), f.late = end["late_wakeups"].get<std::uint64_t>(), f.samples = end["samples"].get<std::uint64_t>();
  if (!lab.is_null()) f.lab = nlohmann::json::parse(c.Get("/api/status")->body)["lab"];
  c.Post(("/api/campaigns/" + std::to_string(id) + "/abort").c_str());
  return f;
}
}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int k = 1; k + 1 < argc; k += 2) {
    const std::string a = argv[k];
    if (a == "--samples")
      o.samples = std::atoll(argv[k + 1]);
    else if (a == "--reps")
      o.reps = std::atoi(argv[k + 1]);
    else if (a == "--campaign-seconds")
      o.campaign_s = std::atof(argv[k + 1]);
    else if (a == "--replicate-every-s")
      o.replicate_every_s = std::atof(argv[k + 1]);
    else {
      std::fprintf(stderr, "usage: bench_replication [--samples N] [--reps K] [--campaign-seconds S] [--replicate-every-s P]\n");
      return 2;
    }
  }
  const auto wall = Clock::now();
  try {
    auto server = std::make_unique<PostgresServer>();
    TempDir dir("bench-replication");
    const std::string path = (dir / "daemon.db").string();
    auto t0 = Clock::now();
    fill(path, o);
    const std::int64_t per_run = o.samples / o.runs, rows = per_run * o.runs;
    {  // 1 and 2: throughput, interleaved.
      Lab lab(*server);
      std::printf("SQLite store: %lld samples in %d runs, filled in %.1f s; PostgreSQL %d on loopback (the tests' server: fsync off); COPYs of %zu rows\n",
                  static_cast<long long>(rows), o.runs, since(t0), lab.pg.server_version() / 10000, o.batch);
      sqlite3* lite = nullptr;
      if (sqlite3_open_v2(path.c_str(), &lite, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) throw std::runtime_error("cannot open the store");
      std::vector<double> bare_rate, rep_rate, rep_s;
      int next_daemon = 1000;  // the bare copies' daemon ids, apart from the replicator's
      for (int rep = 0; rep < o.reps; ++rep) {
        for (int side = 0; side < 2; ++side) {
          const bool bare = (side == 0) == (rep % 2 == 0);
          lab.empty();
          int daemon_id = 0;
          double s = 0;
          if (bare) {
            daemon_id = ++next_daemon;
            t0 = Clock::now();
            const std::int64_t n = bare_copy(lite, lab.raw, daemon_id, o.batch);
            s = since(t0);
            if (n != rows) throw std::runtime_error("bare read " + std::to_string(n) + " rows");
            bare_rate.push_back(static_cast<double>(rows) / s);
          } else {
            hystlab::db::Replicator r(path, {"bench-lab", "bench-rep-" + std::to_string(rep), "bench", ""}, server->url(), PostgresServer::kPassword, o.batch);
            r.connect();
            daemon_id = r.daemon_id();
            int passes = 0;
            t0 = Clock::now();
            while (!r.pass(10).caught_up) ++passes;
            s = since(t0);
            rep_rate.push_back(static_cast<double>(rows) / s), rep_s.push_back(s);
            if (r.backlog_samples() != 0) throw std::runtime_error("replicator: a backlog after catching up");
          }
          const std::int64_t got = lab.count(daemon_id);
          if (got != rows) throw std::runtime_error(std::string(bare ? "bare" : "replicator") + ": " + std::to_string(got) + " rows in PostgreSQL");
          std::printf("  repetition %d, %-10s %6.2f s  %8.0f rows/s\n", rep + 1, bare ? "bare:" : "replicator:", s, static_cast<double>(rows) / s);
        }
      }
      // Bytes a sample row takes (after the last repetition: exactly `rows` rows, then ANALYZEd).
      lab.pg.exec("VACUUM ANALYZE hystlab.samples");
      const hystlab::db::PgResult size = lab.pg.query(
          "SELECT sum(pg_relation_size(relid)), sum(pg_indexes_size(relid)), sum(pg_total_relation_size(relid)) "
          "FROM pg_partition_tree('hystlab.samples') WHERE isleaf");
      const double heap_b = static_cast<double>(size.integer(0, 0)), index_b = static_cast<double>(size.integer(0, 1)),
                   total_b = static_cast<double>(size.integer(0, 2));

      // Where the time goes: SQLite read + encode alone; COPY of the same text pre-encoded alone.
      t0 = Clock::now();
      std::size_t bytes = 0;
      std::vector<std::string> batches(1);
      scan_encode(lite, 999, o.batch, [&](const std::string& b, bool end) {
        batches.back() += b;
        bytes += b.size();
        if (end) batches.emplace_back();
      });
      const double encode_s = since(t0);
      lab.empty();
      t0 = Clock::now();
      for (const std::string& b : batches) {
        if (b.empty()) continue;
        check(PQexec(lab.raw, "COPY hystlab.samples(daemon_id, run_id, seq, t, cmd, disp, force, status) FROM STDIN"), PGRES_COPY_IN, lab.raw);
        PQputCopyData(lab.raw, b.data(), static_cast<int>(b.size()));
        PQputCopyEnd(lab.raw, nullptr);
        check(PQgetResult(lab.raw), PGRES_COMMAND_OK, lab.raw);
        while (PGresult* x = PQgetResult(lab.raw)) PQclear(x);
      }
      const double copy_s = since(t0);
      batches.clear();
      sqlite3_close(lite);

      const double bare_med = median(bare_rate), rep_med = median(rep_rate), ratio = rep_med / bare_med;
      std::printf("\n1. replication throughput of samples, median of %d interleaved repetitions each:\n", o.reps);
      std::printf("   bare COPY %.0f rows/s, replicator %.0f rows/s: ratio replicator/bare %.2f (target >= 0.8: %s)\n", bare_med, rep_med, ratio,
                  met(ratio >= 0.8));
      std::printf(
          "   where the time goes (%lld rows, %.0f bytes of COPY text a row): SQLite read + encode alone %.2f s, COPY of the pre-encoded text alone %.2f s;\n",
          static_cast<long long>(rows), static_cast<double>(bytes) / static_cast<double>(rows), encode_s, copy_s);
      std::printf("   the bare code streams each row into the open COPY (the two overlap); the replicator encodes a batch, then sends it\n");
      std::printf("2. catch-up of a %lld-sample backlog (replicator, a fresh daemon): median %.2f s, %.0f rows/s\n", static_cast<long long>(rows),
                  median(rep_s), rep_med);
      std::printf("   a sample row in PostgreSQL: %.1f bytes (table %.1f + primary key %.1f; pg_total_relation_size of the 16 partitions / rows)\n",
                  total_b / static_cast<double>(rows), heap_b / static_cast<double>(rows), index_b / static_cast<double>(rows));
    }

    // 3. Lag and missed deadlines during a 1 kHz campaign. The lab's servers anew, started from
    // a thread kept off the acquisition CPU at the lowest priority: they inherit both.
    setenv("HYSTLAB_BENCH_PG_PASSWORD", PostgresServer::kPassword, 1);
    std::unique_ptr<MosquittoBroker> broker;
    server.reset();
    std::thread([&] {
      off_acquisition_cpu();
      server = std::make_unique<PostgresServer>();
      broker = std::make_unique<MosquittoBroker>();
    }).join();
    const CampaignFigures base = campaign(nullptr, o.campaign_s);
    std::printf("3. a 1 kHz FOT campaign on a simulated load frame in real time, %.0f s a daemon, one daemon after the other:\n", o.campaign_s);
    std::printf("   without a lab section (the baseline): %llu missed deadlines (%llu samples, %llu late wake-ups)\n",
                static_cast<unsigned long long>(base.missed), static_cast<unsigned long long>(base.samples), static_cast<unsigned long long>(base.late));
    long long added = 0;
    // replicate_every_s: the default (the section without it), then the period asked for, if any.
    std::vector<double> periods{0.0};
    if (o.replicate_every_s > 0) periods.push_back(o.replicate_every_s);
    for (const double period : periods) {
      const std::string name = "bench-pc-" + std::to_string(period == 0 ? 1 : 2);  // a daemon's own marks: one name a database
      nlohmann::json section{{"name", "bench-lab"},
                             {"daemon", name},
                             {"postgresql", server->url()},
                             {"postgresql_password_env", "HYSTLAB_BENCH_PG_PASSWORD"},
                             {"mqtt", {{"host", "127.0.0.1"}, {"port", broker->port()}}}};
      if (period > 0) section["replicate_every_s"] = period;
      const CampaignFigures with = campaign(section, o.campaign_s);
      const auto& pgs = with.lab["postgresql"];
      const auto& mq = with.lab["mqtt"];
      if (with.lag_s.empty() || pgs["samples"].get<std::int64_t>() == 0 || mq["published"].get<std::int64_t>() == 0)
        throw std::runtime_error("the lab daemon replicated or published nothing: " + with.lab.dump());
      const double p50 = quantile(with.lag_s, 0.5), p99 = quantile(with.lag_s, 0.99);
      std::printf(
          "   with lab.postgresql (replicate_every_s %s) and lab.mqtt: %lld samples replicated in %lld passes, %lld MQTT messages published, %lld dropped\n",
          period > 0 ? std::to_string(period).substr(0, 4).c_str() : "1, the default", static_cast<long long>(pgs["samples"].get<std::int64_t>()),
          static_cast<long long>(pgs["passes"].get<std::int64_t>()), static_cast<long long>(mq["published"].get<std::int64_t>()),
          static_cast<long long>(mq["dropped"].get<std::int64_t>()));
      std::printf("     replication lag over %zu readings every 100 ms: p50 %.3f s, p99 %.3f s, max %.3f s (target p99 < 1 s: %s)\n", with.lag_s.size(), p50,
                  p99, quantile(with.lag_s, 1.0), met(p99 < 1.0));
      std::printf("     missed deadlines %llu (%llu samples, %llu late wake-ups)\n", static_cast<unsigned long long>(with.missed),
                  static_cast<unsigned long long>(with.samples), static_cast<unsigned long long>(with.late));
      added = std::max(added, static_cast<long long>(with.missed) - static_cast<long long>(base.missed));
    }
    std::printf(
        "   (lag_s: the age of the newest instant at which everything SQLite held was in PostgreSQL, the start of the newest\n"
        "    pass that left nothing behind; by construction it runs from one pass's time up to replicate_every_s plus two passes')\n");
    std::printf("   missed deadlines added by replication and MQTT together (the larger of the two, against the baseline): %lld (target 0: %s)\n", added,
                met(added <= 0));
    std::printf("wall time of the benchmark: %.0f s\n", since(wall));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_replication: %s\n", e.what());
    return 1;
  }
}
