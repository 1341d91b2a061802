#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "hystlab/models/lsq_fit.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/relay_grid.hpp"
#include "test_support.hpp"

using namespace hystlab::models;

TEST_CASE("preisach: memory-stack evaluation equals a brute-force relay simulation (randomized)") {
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    const int n = 3 + static_cast<int>(seed % 9);
    CAPTURE(n);
    const Grid g = Grid::make(0.0, 4.0, n);
    RelayGrid relays(hystlab::test::random_relays(rng, g));
    PreisachModel model(relays.everett_table(g));
    const auto input = hystlab::test::random_node_inputs(rng, g, 3000);
    double worst = 0.0;
    for (std::size_t k = 0; k < input.size(); ++k) {
      const double expected = relays.step(input[k]);
      const double got = model.step(input[k]);
      worst = std::max(worst, std::fabs(got - expected));
    }
    CHECK(worst < 1e-9);
  }
}

TEST_CASE("preisach: the regressor form (O(depth) re-statement of Eqs. 6-7) equals the incremental model") {
  std::mt19937_64 rng(99);
  const Grid g = Grid::make(0.0, 4.0, 9);
  const EverettTable t = RelayGrid(hystlab::test::random_relays(rng, g)).everett_table(g);
  PreisachModel model(t);
  const auto input = hystlab::test::random_ramps(rng, -0.3, 4.3, 80, 0.037);
  const auto rows = preisach_regressors(g, input);
  for (std::size_t k = 0; k < input.size(); ++k) {
    double v = 0.0;
    for (const auto& term : rows[k]) v += term.weight * t.values()[term.node];
    CAPTURE(k);
    REQUIRE(model.step(input[k]) == doctest::Approx(v).epsilon(1e-10));
  }
}

TEST_CASE("preisach: wiping-out: returning to a turning point restores its force and memory") {
  std::mt19937_64 rng(5);
  const Grid g = Grid::make(0.0, 4.0, 10);
  PreisachModel m(RelayGrid(hystlab::test::random_relays(rng, g)).everett_table(g));
  m.step(3.0);
  const double f_at_M = m.step(3.0);
  const auto depth_at_M = m.depth();
  m.step(3.1);  // push on, then come back down to the same level from above? no: go below and form loops
  m.step(1.0);
  const double f_at_m = m.output();
  for (double x : {2.5, 1.5, 2.2, 1.8, 2.0}) m.step(x);  // nested minor loops inside (1.0, 3.1)
  CHECK(m.depth() > depth_at_M);
  m.step(1.0);  // back to the minimum: the inner loops are wiped
  CHECK(m.output() == doctest::Approx(f_at_m).epsilon(1e-12));
  m.step(3.1);
  m.step(3.0);
  CHECK(m.output() != doctest::Approx(f_at_M));  // memory: the descending branch differs from the ascending one
  m.step(4.0);
  CHECK(m.depth() == 1);  // the maximum of the range wipes every pair
  m.step(0.0);
  CHECK(m.output() == doctest::Approx(0.0));
  CHECK(m.depth() == 1);
}

TEST_CASE("preisach: congruency: minor loops between the same extrema differ only by a shift") {
  std::mt19937_64 rng(17);
  const Grid g = Grid::make(0.0, 4.0, 12);
  const EverettTable t = RelayGrid(hystlab::test::random_relays(rng, g)).everett_table(g);
  auto loop_shape = [&](std::vector<double> history) {
    PreisachModel m(t);
    for (double x : history) m.step(x);
    std::vector<double> shape;
    const double f0 = m.step(1.5);
    for (double x = 1.5; x <= 2.5 + 1e-12; x += 0.05) shape.push_back(m.step(x) - f0);
    for (double x = 2.5; x >= 1.5 - 1e-12; x -= 0.05) shape.push_back(m.step(x) - f0);
    return shape;
  };
  const auto a = loop_shape({3.8, 0.2, 2.9});       // approach 1.5 from above after a big loop
  const auto b = loop_shape({1.0, 3.2, 0.6, 3.0});  // a different history, same extrema 1.5 / 2.5
  REQUIRE(a.size() == b.size());
  for (std::size_t k = 0; k < a.size(); ++k) CHECK(a[k] == doctest::Approx(b[k]).epsilon(1e-10));
}

TEST_CASE("preisach: continuity on random ramps (randomized)") {
  for (std::uint64_t seed = 21; seed < 26; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    const Grid g = Grid::make(0.0, 4.0, 8);
    const EverettTable t = RelayGrid(hystlab::test::random_relays(rng, g)).everett_table(g);
    double total = 0.0;
    for (double v : t.values()) total = std::max(total, v);
    PreisachModel m(t);
    const auto in = hystlab::test::random_ramps(rng, 0.0, 4.0, 60, 1e-3);
    double prev_x = in.front(), prev_f = m.step(prev_x), worst = 0.0;
    for (double x : in) {
      const double f = m.step(x);
      worst = std::max(worst, std::fabs(f - prev_f) / std::max(1e-12, std::fabs(x - prev_x)));
      prev_x = x;
      prev_f = f;
    }
    // Lipschitz bound: the slope of F is at most total mass per cell width, times 2 for the two terms.
    CHECK(worst < 4.0 * total / g.step());
  }
}

TEST_CASE("preisach: peek predicts step without changing the state") {
  std::mt19937_64 rng(3);
  const Grid g = Grid::make(0.0, 4.0, 6);
  PreisachModel m(RelayGrid(hystlab::test::random_relays(rng, g)).everett_table(g));
  const auto in = hystlab::test::random_ramps(rng, 0.0, 4.0, 30, 0.2);
  for (double x : in) {
    const double before = m.output();
    const double predicted = m.peek(x);
    CHECK(m.output() == before);
    CHECK(m.step(x) == predicted);
  }
}

// Every kind of input the step treats apart: the same x again, both ends and beyond, NaN, exactly
// a node, wiggles under the merge tolerance, a small stack cap (merges often), a refined grid.
TEST_CASE("preisach: peek equals step and changes nothing, whatever the input (seeded)") {
  int merged = 0;  // seeds whose stack merged (its cap, or a wiggle under the tolerance)
  for (std::uint64_t seed = 1; seed <= 48; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    const int n = 4 + static_cast<int>(seed % 9);
    const Grid g = seed % 2 ? Grid::make(0.0, 4.0, n) : Grid::refined(0.0, 4.0, n, 1.5, 1.0);
    const PreisachOptions o{seed % 3 ? 0.0 : 0.02, 3 + static_cast<std::size_t>(seed % 4)};
    PreisachModel m(RelayGrid(hystlab::test::random_relays(rng, g)).everett_table(g), o);
    std::uniform_real_distribution<double> u(-0.5, 4.5), wiggle(-0.03, 0.03);
    std::uniform_int_distribution<int> pick(0, 9), node(0, n);
    double x = 2.0;
    for (int k = 0; k < 4000; ++k) {
      const int what = pick(rng);
      if (what == 1) x = g.lo;
      if (what == 2) x = g.hi;
      if (what == 3) x = NAN;
      if (what == 4) x = g.node(node(rng));
      if (what == 5 || what == 6) x = (std::isnan(x) ? 2.0 : x) + wiggle(rng);
      if (what >= 7) x = u(rng);
      CAPTURE(k);
      CAPTURE(x);
      CAPTURE(m.depth());
      const std::vector<double> before = m.save_state();
      const double p = m.peek(x);
      REQUIRE(m.save_state() == before);  // the counters included
      const double s = m.step(x);
      REQUIRE(((std::isnan(p) && std::isnan(s)) || p == s));
    }
    merged += m.merge_count() > 0 ? 1 : 0;
  }
  CHECK(merged >= 36);  // the merging path was taken, not only the plain one (a mutation of it fails here)
}

TEST_CASE("preisach: clamping is counted, NaN is refused, reset clears") {
  const Grid g = Grid::make(1.0, 3.0, 2);
  PreisachModel m(EverettTable(g, {0, 2, 0, 5, 2, 0}));
  m.step(3.5);
  CHECK(m.saturation_count() == 1);
  CHECK(m.input() == 3.0);
  CHECK(m.output() == doctest::Approx(5.0));  // F(δmax, δmin)
  CHECK(std::isnan(m.step(NAN)));
  CHECK(m.invalid_input_count() == 1);
  CHECK(m.input() == 3.0);  // NaN changed nothing
  m.step(0.0);
  CHECK(m.saturation_count() == 2);
  CHECK(m.output() == doctest::Approx(0.0));
  m.reset();
  CHECK(m.saturation_count() == 0);
  CHECK(m.depth() == 1);
}

TEST_CASE("preisach: bounded stack: the cap merges the newest excursion and counts it") {
  std::mt19937_64 rng(8);
  const Grid g = Grid::make(0.0, 4.0, 20);
  const EverettTable t = RelayGrid(hystlab::test::random_relays(rng, g)).everett_table(g);
  PreisachModel capped(t, PreisachOptions{0.0, 9});
  PreisachModel exact(t);
  // A converging oscillation creates ever deeper nested pairs.
  double worst = 0.0;
  for (int k = 0; k < 40; ++k) {
    const double x = 2.0 + ((k % 2) ? 1.0 : -1.0) * 1.9 * std::pow(0.85, k);
    capped.step(x);
    exact.step(x);
    CHECK(capped.depth() <= 9);
    worst = std::max(worst, std::fabs(capped.output() - exact.output()));
  }
  CHECK(exact.depth() > 9);
  CHECK(capped.merge_count() > 0);
  CHECK(worst < 0.05 * t.node_value(20, 0));  // merged loops are the smallest: the error stays small
}

TEST_CASE("preisach: merge tolerance forgets excursions smaller than it") {
  const Grid g = Grid::make(0.0, 4.0, 4);
  std::mt19937_64 rng(4);
  PreisachModel m(RelayGrid(hystlab::test::random_relays(rng, g)).everett_table(g), PreisachOptions{0.01, 64});
  m.step(3.0);
  m.step(2.0);
  m.step(2.005);  // a 5 µm wiggle: noise
  m.step(1.5);
  CHECK(m.merge_count() == 1);
  CHECK(m.depth() == 2);  // m0 and the maximum 3.0 only
}

// A step along a branch within the input's cell reads F from what the step kept of that cell
// (EverettTable::in_cell, cell_value); restore_state keeps no cell, so a model restored from the
// same state reads F by the whole rule. The two must agree to the bit, with the state after, on
// every kind of cell: rectangles and the diagonal's triangles, rising and falling, uniform and
// refined grids, smooth inputs (tens of steps a cell, where the kept cell is read: counted), jumps,
// NaN, inputs beyond the ends, nodes, and merges (a small stack cap, a merge tolerance).
TEST_CASE("preisach: a step from the branch's kept cell equals the whole rule's, to the bit (seeded)") {
  int kept[2][2][2] = {};  // [uniform][triangle][rising]: steps whose input was in the kept cell
  for (std::uint64_t seed = 1; seed <= 24; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    const int n = 3 + static_cast<int>(seed % 7);
    const Grid g = seed % 2 ? Grid::make(0.0, 4.0, n) : Grid::refined(0.0, 4.0, n, 2.0, 1.0);
    const EverettTable table = RelayGrid(hystlab::test::random_relays(rng, g)).everett_table(g);
    const PreisachOptions o = seed % 3 ? PreisachOptions{} : PreisachOptions{0.02, 3 + static_cast<std::size_t>(seed % 4)};
    PreisachModel m(table, o);
    std::uniform_real_distribution<double> centre(0.3, 3.7), stroke(0.01, 1.5), jump(-0.5, 4.5);
    std::uniform_int_distribution<int> node(0, n);
    double c = centre(rng), a = stroke(rng), phase = 0.0;
    for (int k = 0; k < 3000; ++k) {
      if (k % 500 == 0) c = centre(rng), a = stroke(rng);  // a new sine: new turning points, other cells
      phase += 2.0 * std::numbers::pi / 97.0;              // 97 steps a period: several a cell
      double x = std::clamp(c + a * std::sin(phase), 0.0, 4.0);
      if (k % 61 == 60) x = k % 4 == 0 ? NAN : k % 4 == 1 ? g.node(node(rng)) : jump(rng);  // beyond the ends too
      CAPTURE(k);
      CAPTURE(x);
      const bool up = x > m.input();
      if (x >= 0.0 && x <= 4.0 && up == static_cast<bool>(m.depth() & 1U) && EverettTable::in_cell(m.kept_cell(), up, table.coordinate(x)))
        ++kept[g.uniform()][m.kept_cell().kind == BranchCell::Kind::triangle][up];
      PreisachModel whole(table, o);
      whole.restore_state(m.save_state());
      const double by_cell = m.step(x), anew = whole.step(x);
      REQUIRE(((std::isnan(by_cell) && std::isnan(anew)) || by_cell == anew));
      // Whole: the saved state is the memory alone (a falling model's scratch slot saved as 0),
      // and the restored model, whose scratch is 0, steps as the one that kept its own.
      REQUIRE(m.save_state() == whole.save_state());
    }
  }
  for (int uniform = 0; uniform < 2; ++uniform)
    for (int triangle = 0; triangle < 2; ++triangle)
      for (int rising = 0; rising < 2; ++rising) {
        CAPTURE(uniform);
        CAPTURE(triangle);
        CAPTURE(rising);
        CHECK(kept[uniform][triangle][rising] > 100);  // each kind of kept cell read, not only the whole rule
      }
}
