// The run's record in chunks (run_series.hpp): what a reader was given never changes, whatever
// the producer appends or thins after; a copy shares and then diverges; and a reader on another
// thread needs no lock (the TSan tree runs this file).
#include <doctest/doctest.h>

#include <random>
#include <thread>

#include "hystlab/daemon/run_series.hpp"

using hystlab::daemon::Columns;
using hystlab::daemon::RunSeries;

namespace {
void fill(RunSeries& s, std::size_t from, std::size_t n) {
  for (std::size_t i = from; i < from + n; ++i) s.add(static_cast<double>(i), -static_cast<double>(i));
}
}  // namespace

TEST_CASE("a shared record keeps what it was given while the series grows, across chunks") {
  const std::uint64_t seed = 7;
  CAPTURE(seed);
  std::mt19937_64 rng(seed);
  for (int round = 0; round < 20; ++round) {
    const std::size_t first = rng() % (3 * RunSeries::kChunk), more = rng() % (3 * RunSeries::kChunk);
    CAPTURE(first);
    CAPTURE(more);
    RunSeries s;
    fill(s, 0, first);
    const RunSeries::Shared seen = s.share();
    fill(s, first, more);
    REQUIRE(seen.size == first);
    REQUIRE(s.size() == first + more);
    for (std::size_t i = 0; i < first; ++i) REQUIRE(seen.x(i) == static_cast<double>(i));
    for (std::size_t i = 0; i < first + more; ++i) REQUIRE(s.f(i) == -static_cast<double>(i));
    Columns c;
    s.copy(first / 2, first + more, c);
    REQUIRE(c.x.size() == first + more - first / 2);
    if (!c.x.empty()) CHECK(c.x.front() == static_cast<double>(first / 2));
  }
}

TEST_CASE("a copy shares its chunks and diverges from the original when either is appended to") {
  RunSeries a;
  fill(a, 0, RunSeries::kChunk + 10);
  RunSeries b = a;
  a.add(1e6, 1e6);
  b.add(-1e6, -1e6);
  CHECK(a.x(RunSeries::kChunk + 10) == 1e6);
  CHECK(b.x(RunSeries::kChunk + 10) == -1e6);
  CHECK(a.x(RunSeries::kChunk + 9) == b.x(RunSeries::kChunk + 9));
}

TEST_CASE("thinning at the bound: every other sample kept, a shared record untouched, indices counted") {
  RunSeries s;
  fill(s, 0, RunSeries::kMaxSamples);
  const RunSeries::Shared before = s.share();
  s.add(-1, -1);  // over the bound: the record is thinned 2:1 first, then this sample kept
  CHECK(s.halvings() == 1);
  CHECK(s.stride() == 2);
  CHECK(s.size() == RunSeries::kMaxSamples / 2 + 1);
  CHECK(s.x(1) == 2.0);
  CHECK(s.x(RunSeries::kMaxSamples / 2) == -1.0);
  CHECK(before.size == RunSeries::kMaxSamples);
  CHECK(before.x(RunSeries::kMaxSamples - 1) == static_cast<double>(RunSeries::kMaxSamples - 1));
  s.add(5, 5);  // from now on every second sample offered is kept: this one is not
  CHECK(s.size() == RunSeries::kMaxSamples / 2 + 1);
  s.add(6, 6);
  CHECK(s.size() == RunSeries::kMaxSamples / 2 + 2);
  CHECK(s.x(RunSeries::kMaxSamples / 2 + 1) == 6.0);
  const Columns few = before.thinned(1000);
  CHECK(few.x.size() <= 1000);
  CHECK(few.x.size() > 900);
  CHECK(few.x.front() == 0.0);
}

TEST_CASE("a reader on another thread scores what it was given while the producer appends") {
  RunSeries s;
  fill(s, 0, 50'000);
  double sum_seen = 0;
  std::thread reader;
  {
    const RunSeries::Shared shared = s.share();
    reader = std::thread([shared, &sum_seen] {
      const Columns c = shared.thinned(1u << 20);
      for (const double v : c.x) sum_seen += v;
    });
  }
  fill(s, 50'000, 3 * RunSeries::kChunk);  // into the chunk the reader holds: a private copy first
  reader.join();
  CHECK(sum_seen == doctest::Approx(49'999.0 * 50'000.0 / 2));
  CHECK(s.x(50'001) == 50'001.0);
}
