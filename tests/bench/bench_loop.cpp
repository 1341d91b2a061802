// GET /api/runs/ID/loop on a stored run of 10^7 samples (a FOT input read back from the store):
// the time to return 2,000 points of its x-y path with every reversal kept, next to the
// samples overview of the same run (2,000 min/max buckets from the block summaries, the cheapest
// read the API has), in the same run. The first loop request reads the run from SQLite into
// memory (its time is printed too); later ones decimate from memory. Target: < 100 ms.
// It asserts agreement (every reversal of the stored input is in the answer), never speed.
#include <httplib.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "../support/daemon_process.hpp"
#include "hystlab/db/store.hpp"
#include "hystlab/models/simplified_sma.hpp"

using nlohmann::json;

namespace {
constexpr int kRows = 12;

// rows rises and descents over 0..14 mm, samples spread evenly over the path's length.
void fill(const std::string& path, std::int64_t n) {
  hystlab::db::Store store(path, false);
  const std::string now = "2026-01-01T00:00:00Z";
  const auto rig = store.upsert_rig("sim frame", "{}", now);
  const auto campaign =
      store.create_campaign(rig, hystlab::domain::CampaignKind::fot, R"({"kind":"fot","range_mm":[0,14],"subdivisions":12,"ramp_rate_mm_s":0.5})", now);
  const auto run = store.add_run(campaign, now, 0, 0);
  hystlab::models::SimplifiedSmaModel m(hystlab::models::table1_parameters());
  double total = 0;
  for (int i = 1; i <= kRows; ++i) total += 2 * 14.0 * i / kRows;
  std::vector<hystlab::db::SampleRow> rows;
  rows.reserve(100'000);
  std::int64_t seq = 0;
  auto flush = [&] {
    hystlab::db::Transaction tx(store.database());
    store.insert_samples(rows);
    tx.commit();
    rows.clear();
  };
  for (int i = 1; i <= kRows; ++i) {
    const double top = 14.0 * i / kRows;
    const auto leg = static_cast<std::int64_t>(static_cast<double>(n) * top / total);
    for (int dir = 0; dir < 2; ++dir)
      for (std::int64_t k = 0; k < leg; ++k) {
        const double x = dir == 0 ? top * static_cast<double>(k) / static_cast<double>(leg) : top * (1 - static_cast<double>(k) / static_cast<double>(leg));
        rows.push_back({run, seq, static_cast<double>(seq) * 1e-3, x, x, m.step(x), 5});
        ++seq;
        if (rows.size() == rows.capacity()) flush();
      }
  }
  rows.push_back({run, seq, static_cast<double>(seq) * 1e-3, 0, 0, m.step(0), 5});
  flush();
  store.end_run(run, hystlab::domain::CampaignState::completed, now);
  store.transition(campaign, hystlab::domain::CampaignState::completed, "stored by bench_loop", now);
  std::printf("stored run %lld: %lld samples\n", static_cast<long long>(run), static_cast<long long>(seq + 1));
}

double get_ms(httplib::Client& c, const std::string& path, json* body = nullptr) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = c.Get(path.c_str());
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!r || r->status != 200) throw std::runtime_error("GET " + path + " failed" + (r ? ": " + r->body : std::string()));
  if (body) *body = json::parse(r->body);
  return ms;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
}  // namespace

int main(int argc, char** argv) {
  // --fill PATH N: only store a completed campaign of about N samples in PATH and exit (the
  // seeding of bench_page.mjs). The file is created if need be; each call adds a campaign with
  // one run, on the rig "sim frame" (shared). From 200 samples every leg has some.
  for (int k = 1; k < argc; ++k)
    if (std::string(argv[k]) == "--fill") {
      if (k + 2 >= argc || std::atoll(argv[k + 2]) < 200) {
        std::fprintf(stderr, "usage: bench_loop --fill PATH N (N >= 200)\n");
        return 2;
      }
      try {
        fill(argv[k + 1], std::atoll(argv[k + 2]));
      } catch (const std::exception& e) {
        std::printf("FAIL: %s\n", e.what());
        return 1;
      }
      return 0;
    }
  std::int64_t n = 10'000'000;
  for (int k = 1; k + 1 < argc; ++k)
    if (std::string(argv[k]) == "--samples") n = std::atoll(argv[k + 1]);
  try {
    const auto t0 = std::chrono::steady_clock::now();
    hystlab::test_support::DaemonProcess d(R"({"rigs": [{"name": "sim frame", "simulate": {"time_scale": 10}}]})", [n](const std::string& p) { fill(p, n); });
    std::printf("stored in %.1f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    httplib::Client c("127.0.0.1", d.port());
    c.set_read_timeout(600, 0);
    json loop;
    const double cold = get_ms(c, "/api/runs/1/loop?points=2000", &loop);
    std::vector<double> warm, base;
    for (int k = 0; k < 7; ++k) {
      base.push_back(get_ms(c, "/api/runs/1/samples?points=2000"));
      warm.push_back(get_ms(c, "/api/runs/1/loop?points=2000", &loop));
    }
    const std::size_t reversals = loop["reversals"], points = loop["points"];
    std::printf("loop endpoint, %lld samples -> %zu points (%zu reversals): first request %.0f ms (reads the run into memory), then median %.1f ms\n",
                static_cast<long long>(n), points, reversals, cold, median(warm));
    std::printf("baseline: the samples overview, 2,000 min/max buckets of the same run: median %.1f ms\n", median(base));
    std::printf("ratio loop / overview: %.2f (target: the loop under 100 ms: %s)\n", median(warm) / median(base), median(warm) < 100 ? "met" : "NOT met");
    if (reversals != 2 * kRows - 1) {
      std::printf("FAIL: %zu reversals in the answer, the stored input has %d\n", reversals, 2 * kRows - 1);
      return 1;
    }
  } catch (const std::exception& e) {
    std::printf("FAIL: %s\n", e.what());
    return 1;
  }
  return 0;
}
