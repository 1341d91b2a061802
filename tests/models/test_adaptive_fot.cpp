// Issue 41: the adaptive FOT campaign's rule (models/adaptive_fot.hpp) on tables built node by
// node from known surfaces: the rows measured, their table on its own grid, the next row, the
// stops, and the force noise a record carries.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <random>

#include "hystlab/models/adaptive_fot.hpp"

using namespace hystlab::models;

namespace adaptive_fot_test {  // named: the unity build puts test_fot_design.cpp's helpers beside these

// F(α, β) = φ(α) − φ(β); one sharp bend: 5 N/mm below 2.3 mm, 60 above, joined over 0.1 mm.
double bend23(double x) { return 5 * x + 55 * 0.1 * std::log1p(std::exp((x - 2.3) / 0.1)); }

// Row i measured as a descent passes every fine node below its top: f_α = φ(α), f_αβ = φ(β).
void measure_row(OnlineTableBuilder& b, int i, const std::function<double(double)>& phi) {
  const Grid& g = b.grid();
  for (int j = 0; j < i; ++j) REQUIRE_FALSE(b.add({g.node(i), g.node(j), phi(g.node(i)), phi(g.node(j))}));
}

// The fine builder after the coarse rows (every `stride`-th node).
OnlineTableBuilder coarse(int fine_n, int stride, const std::function<double(double)>& phi) {
  OnlineTableBuilder b(Grid::make(0.0, 4.0, fine_n));
  for (int i = stride; i <= fine_n; i += stride) measure_row(b, i, phi);
  return b;
}

// Runs the design to its end: the rows it chose, in order.
std::vector<int> run(OnlineTableBuilder& b, const AdaptiveOptions& o, const std::function<double(double)>& phi, AdaptiveStep& last) {
  std::vector<int> rows;
  for (int k = 0; k < 200; ++k) {
    last = next_row(b, o);
    if (!last.row) return rows;
    REQUIRE_FALSE(b.identified(*last.row, 0));  // never a row measured before
    rows.push_back(*last.row);
    measure_row(b, *last.row, phi);
  }
  FAIL("the design never stopped");
  return rows;
}

}  // namespace adaptive_fot_test
using namespace adaptive_fot_test;

TEST_CASE("the rows measured whole and their table on its own grid: the fine builder's nodes, carried over exactly") {
  OnlineTableBuilder b = coarse(16, 4, bend23);
  // A row with a hole (node (6, 2) missing) is not measured.
  const Grid& g = b.grid();
  for (int j = 0; j < 6; ++j)
    if (j != 2) REQUIRE_FALSE(b.add({g.node(6), g.node(j), bend23(g.node(6)), bend23(g.node(j))}));
  CHECK(measured_rows(b) == std::vector<int>{0, 4, 8, 12, 16});
  const std::optional<OnlineTableBuilder> rows = rows_builder(b);
  REQUIRE(rows);
  CHECK(rows->complete());
  CHECK(rows->grid().n == 4);
  const EverettTable t = rows->table();
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= i; ++j) {
      CAPTURE(i);
      CAPTURE(j);
      CHECK(t.node_value(i, j) == doctest::Approx(bend23(i * 1.0) - bend23(j * 1.0)).epsilon(1e-12));
    }
  // Row 10 added: a non-uniform grid (format v2) with its node read from the earlier descents.
  measure_row(b, 10, bend23);
  const std::optional<OnlineTableBuilder> more = rows_builder(b);
  REQUIRE(more);
  CHECK_FALSE(more->grid().uniform());
  CHECK(more->grid().n == 5);
  CHECK(more->table().node_value(4, 3) == doctest::Approx(bend23(3.0) - bend23(2.5)));  // F(δ=3, β=2.5): row 12 read at the new node
  // Without the top row there is no table yet.
  OnlineTableBuilder partial(Grid::make(0.0, 4.0, 16));
  measure_row(partial, 8, bend23);
  CHECK_FALSE(rows_builder(partial));
  CHECK(next_row(partial, {}).stopped.find("top row") != std::string::npos);
}

TEST_CASE("on a noiseless surface with one sharp bend the design puts its rows at the bend, its estimate falls, and it stops on resolution or gain") {
  OnlineTableBuilder b = coarse(64, 16, bend23);  // coarse rows at 1, 2, 3, 4 mm; tops on 1/16 mm
  AdaptiveOptions o;
  o.budget_s = 1e6, o.min_gain = 1e-4, o.ramp_mm_s = 0.2;
  const double first = next_row(b, o).estimated_rms_N;
  AdaptiveStep last;
  const std::vector<int> rows = run(b, o, bend23, last);
  CAPTURE(last.stopped);
  REQUIRE(rows.size() >= 6);
  int near = 0;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const double at = b.grid().node(rows[k]);
    CAPTURE(k);
    CAPTURE(at);
    // The first rows go to the bend's band [2, 3] mm or the one below it (its divided differences
    // reach the bend; a row there is cheaper): measured 1.5, 2.5, 2.25, 2.75, 1.75, 2.125 mm.
    if (k < 6) CHECK(std::fabs(at - 2.3) < 0.85);
    near += std::fabs(at - 2.3) < 0.7 ? 1 : 0;
  }
  CAPTURE(near);
  CAPTURE(rows.size());
  CHECK(near * 3 >= static_cast<int>(rows.size()) * 2);  // 1.4 mm of the 4: a uniform grid would put 35 % of its rows there
  CHECK(last.estimated_rms_N < 0.05 * first);
  CHECK((last.stopped.rfind("resolution", 0) == 0 || last.stopped.rfind("gain", 0) == 0));
}

TEST_CASE("the design stops on its target, its budget and its gain, and says which") {
  AdaptiveOptions o;
  o.ramp_mm_s = 0.2, o.settle_s = 1.0, o.noise_N = 0.05;
  SUBCASE("target: reached once the estimate is at or below it") {
    OnlineTableBuilder b = coarse(32, 8, bend23);
    o.budget_s = 1e6;
    o.target_rms_N = 0.5 * next_row(b, o).estimated_rms_N;
    AdaptiveStep last;
    const std::vector<int> rows = run(b, o, bend23, last);
    CHECK(!rows.empty());
    CHECK(last.stopped.rfind("target", 0) == 0);
    CHECK(last.estimated_rms_N <= o.target_rms_N);
  }
  SUBCASE("target below the noise: refused at once, the field named") {
    OnlineTableBuilder b = coarse(32, 8, bend23);
    o.budget_s = 1e6, o.target_rms_N = 0.04;
    AdaptiveStep last;
    CHECK(run(b, o, bend23, last).empty());
    CHECK(last.stopped.find("target_rms_N") != std::string::npos);
    CHECK(last.stopped.find("noise") != std::string::npos);
  }
  SUBCASE("budget: the rows' rig time by the cost model never passes it") {
    OnlineTableBuilder b = coarse(32, 8, bend23);
    const double coarse_s = next_row(b, o).spent_s;
    CHECK(coarse_s == doctest::Approx(2 * (1 + 2 + 3 + 4) / 0.2 + 4 * 1.0));
    o.budget_s = coarse_s + 60, o.min_gain = 1e-4;
    AdaptiveStep last;
    const std::vector<int> rows = run(b, o, bend23, last);
    CHECK(!rows.empty());
    CHECK(last.spent_s <= o.budget_s);
    CAPTURE(last.stopped);
    CHECK(last.stopped.rfind("budget", 0) == 0);
  }
  SUBCASE("gain: no row would remove min_gain of the estimated squared error left") {
    OnlineTableBuilder b = coarse(32, 8, [](double x) { return 10 * x; });  // flat: nothing to gain
    o.budget_s = 1e6;
    AdaptiveStep last;
    CHECK(run(
              b, o, [](double x) { return 10 * x; }, last)
              .empty());
    CHECK(last.stopped.rfind("gain", 0) == 0);
    CHECK(last.estimated_rms_N == doctest::Approx(o.noise_N));
  }
}

TEST_CASE("the force noise of a record along slow ramps, with turning points and a bend: within 5 % of the σ put in") {
  for (const std::uint64_t seed : {1U, 2U, 3U}) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise(0.0, 0.05);
    std::vector<double> f;
    for (int k = 0; k < 40'000; ++k) {  // 0 → 4 → 0 mm and again at 0.2 mm/s and 1 kHz
      const double t = k * 1e-3, x = 4 - std::fabs(std::fmod(0.2 * t, 8.0) - 4);
      f.push_back(bend23(x) + noise(rng));
    }
    CHECK(force_noise(f) == doctest::Approx(0.05).epsilon(0.05));
  }
  CHECK(force_noise(std::vector<double>{1, 2}) == 0.0);
}
