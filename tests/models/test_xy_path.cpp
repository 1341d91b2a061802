// Shape-keeping decimation of an x-y path: every reversal of x kept, the budget held, noise
// spending no points, and a Preisach model on the kept points equal to the model on all of them.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/models/xy_path.hpp"

using namespace hystlab::models;

namespace {
// A FOT-like input: rise to δ_i, back to 0, for i = 1..rows, with noise; y a hysteretic force.
void fot_path(int rows, int per_mm, double noise, std::uint32_t seed, std::vector<float>& x, std::vector<float>& y) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0, noise);
  SimplifiedSmaModel m(table1_parameters());
  auto go = [&](double a, double b) {
    const int steps = static_cast<int>(std::abs(b - a) * per_mm) + 1;
    for (int k = 1; k <= steps; ++k) {
      const double v = a + (b - a) * k / steps;
      x.push_back(static_cast<float>(v + n(rng) * 1e-3));
      y.push_back(static_cast<float>(m.step(v) + n(rng)));
    }
  };
  double at = 0;
  for (int i = 1; i <= rows; ++i) {
    const double top = 14.0 * i / rows;
    go(at, top), go(top, 0), at = 0;
  }
}
}  // namespace

TEST_CASE("reduce_path keeps every reversal and holds the budget, over seeded random paths") {
  for (std::uint32_t seed = 1; seed <= 20; ++seed) {
    CAPTURE(seed);
    std::mt19937 rng(seed);
    const int rows = 2 + static_cast<int>(rng() % 12), per_mm = 200 + static_cast<int>(rng() % 3000);
    const double noise = 0.01 * static_cast<double>(rng() % 50);
    CAPTURE(rows);
    CAPTURE(per_mm);
    std::vector<float> x, y;
    fot_path(rows, per_mm, noise, seed, x, y);
    const std::size_t budget = 500 + rng() % 3000;
    const PathReduction r = reduce_path(x, y, budget);
    CHECK(r.reversals == static_cast<std::size_t>(2 * rows - 1));  // each top and each return to 0 but the last
    CHECK(r.index.size() <= budget + 2);
    CHECK(r.index.size() >= std::min(budget, x.size()) / 2);  // the budget is used, not wasted
    CHECK(std::is_sorted(r.index.begin(), r.index.end()));
    CHECK(r.index.front() == 0);
    CHECK(r.index.back() == x.size() - 1);
    for (const std::size_t t : reversals_of(x, 0.01 * 14.0)) CHECK(std::binary_search(r.index.begin(), r.index.end(), t));
  }
}

TEST_CASE("noise during a dwell spends no points; a short path comes back whole") {
  std::vector<float> x, y;
  fot_path(3, 500, 0.0, 1, x, y);
  const std::size_t clean = reduce_path(x, y, 300).index.size();
  std::vector<float> xd(x), yd(y);
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0, 0.05);
  for (int k = 0; k < 100000; ++k) xd.push_back(0.0f), yd.push_back(static_cast<float>(n(rng)));  // a long noisy dwell at the end
  const PathReduction r = reduce_path(xd, yd, 300);
  std::size_t in_dwell = 0;
  for (const std::size_t k : r.index) in_dwell += k >= x.size() ? 1U : 0U;
  CHECK(in_dwell <= 5);
  CHECK(r.index.size() >= clean - 10);
  const std::vector<float> few{0, 1, 2, 1};
  CHECK(reduce_path(few, few, 100).index.size() == 4);
  CHECK(reduce_path(std::vector<float>{}, std::vector<float>{}, 100).index.empty());
}
