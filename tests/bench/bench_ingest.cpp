// Sample ingest: the daemon's writer (ring -> writer thread -> batched transactions with block
// summaries) next to a bare batched SQLite insert (1,000 rows a transaction, WAL, FULL) into the
// same schema, interleaved in the same run. Prints rows/s and the median ratio of the pairs.
#include <sqlite3.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "hystlab/db/sample_writer.hpp"
#include "hystlab/db/store.hpp"

namespace fs = std::filesystem;
using namespace hystlab::db;

namespace {
constexpr std::int64_t kRows = 1'000'000;

std::string fresh(const fs::path& dir, const char* name) {
  const fs::path p = dir / name;
  for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(p.string() + suffix);
  Store s(p.string());  // same schema, migrated
  const auto rig = s.upsert_rig("bench", "{}", "t");
  s.add_run(s.create_campaign(rig, hystlab::domain::CampaignKind::fot, "{}", "t"), "t", 0, 0);
  return p.string();
}

double bare(const std::string& path) {
  sqlite3* db = nullptr;
  sqlite3_open(path.c_str(), &db);
  sqlite3_exec(db, "PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL", nullptr, nullptr, nullptr);
  sqlite3_stmt* ins = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO samples(run_id, seq, t, cmd, disp, force, status) VALUES(?,?,?,?,?,?,?)", -1, &ins, nullptr);
  const auto t0 = std::chrono::steady_clock::now();
  for (std::int64_t k = 0; k < kRows;) {
    sqlite3_exec(db, "BEGIN", nullptr, nullptr, nullptr);
    for (int b = 0; b < 1000; ++b, ++k) {
      sqlite3_bind_int64(ins, 1, 1);
      sqlite3_bind_int64(ins, 2, k);
      sqlite3_bind_double(ins, 3, static_cast<double>(k) * 1e-3);
      sqlite3_bind_double(ins, 4, 1.0);
      sqlite3_bind_double(ins, 5, 2.0);
      sqlite3_bind_double(ins, 6, 3.0);
      sqlite3_bind_int64(ins, 7, 1);
      sqlite3_step(ins);
      sqlite3_reset(ins);
    }
    sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr);
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  sqlite3_finalize(ins);
  sqlite3_close(db);
  return static_cast<double>(kRows) / s;
}

double writer(const std::string& path, double& max_commit_ms, std::uint64_t& full) {
  SampleWriter w(path);
  const auto t0 = std::chrono::steady_clock::now();
  for (std::int64_t k = 0; k < kRows; ++k) {
    const SampleRow r{1, k, static_cast<double>(k) * 1e-3, 1.0, 2.0, 3.0, 1};
    while (!w.try_push(r)) std::this_thread::yield();  // sustained rate: wait for room, count it
  }
  w.flush();
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const WriterStats st = w.stats();
  max_commit_ms = st.max_commit_ms;
  full = st.dropped_full;
  return static_cast<double>(st.written) / s;
}
// A 10^7-sample run: its decimated overview (min/max in 1,000 buckets) from the block summaries,
// next to the same overview computed by scanning the samples (GROUP BY), in the same run.
void overview_of_ten_million(const fs::path& dir) {
  const std::string path = fresh(dir, "big.db");
  Store s(path, false);
  std::vector<SampleRow> rows;
  const std::int64_t n = 10'000'000;
  for (std::int64_t k = 0; k < n; k += 200'000) {
    rows.clear();
    for (std::int64_t j = k; j < k + 200'000; ++j)
      rows.push_back({1, j, static_cast<double>(j) * 1e-3, 0, std::sin(static_cast<double>(j) * 1e-4), std::cos(static_cast<double>(j) * 1e-4), 0});
    Transaction tx(s.database());
    s.insert_samples(rows);
    tx.commit();
  }
  std::vector<double> fast, scan;
  for (int rep = 0; rep < 3; ++rep) {
    auto t0 = std::chrono::steady_clock::now();
    const auto b = s.overview(1, 0, static_cast<double>(n) * 1e-3, 1000);
    fast.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    t0 = std::chrono::steady_clock::now();
    Statement st(s.database(), "SELECT seq / 10000, min(disp), max(disp), min(force), max(force) FROM samples WHERE run_id = 1 GROUP BY 1");
    std::size_t groups = 0;
    while (st.step()) ++groups;
    scan.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    if (b.empty() || groups != 1000) std::printf("overview check failed: %zu buckets, %zu groups\n", b.size(), groups);
  }
  std::sort(fast.begin(), fast.end());
  std::sort(scan.begin(), scan.end());
  std::printf(
      "overview of a 10^7-sample run in 1000 min/max buckets: %.1f ms from the block summaries, %.0f ms by scanning "
      "the samples (median of 3; %.0fx; target: well under a second)\n",
      fast[1], scan[1], scan[1] / fast[1]);
}
}  // namespace

int main() {
  char tmpl[] = "/tmp/hystlab-ingest-XXXXXX";
  const fs::path dir = mkdtemp(tmpl);
  std::vector<double> ratios;
  std::printf("ingest of %lld rows (run, seq, t, cmd, disp, force, status), WAL, synchronous=FULL\n", static_cast<long long>(kRows));
  for (int rep = 0; rep < 3; ++rep) {
    const double b = bare(fresh(dir, "bare.db"));
    double max_ms = 0;
    std::uint64_t full = 0;
    const double w = writer(fresh(dir, "writer.db"), max_ms, full);
    std::printf(
        "bare batched insert (1000/tx): %8.0f k rows/s | SampleWriter: %8.0f k rows/s (max commit %.1f ms, ring-full "
        "retries %llu)\n",
        b / 1e3, w / 1e3, max_ms, static_cast<unsigned long long>(full));
    ratios.push_back(w / b);
  }
  std::sort(ratios.begin(), ratios.end());
  std::printf("writer/bare, median of 3 interleaved pairs: %.0f %% (target >= 50 %%)\n", 100 * ratios[1]);
  overview_of_ten_million(dir);
  fs::remove_all(dir);
  return 0;
}
