// Issue 41: where the next FOT rows go, from an identified table (models/fot_design.hpp).
#include <doctest/doctest.h>

#include <cmath>
#include <functional>

#include "hystlab/models/fot_design.hpp"

using namespace hystlab::models;

namespace {

// A table of F(α, β) = φ(α) − φ(β) (zero on the diagonal) on the grid.
EverettTable table_of(const Grid& g, const std::function<double(double)>& phi) {
  std::vector<double> v(g.node_count());
  for (int i = 0; i <= g.n; ++i)
    for (int j = 0; j <= i; ++j) v[Grid::index(i, j)] = phi(g.node(i)) - phi(g.node(j));
  return EverettTable(g, std::move(v));
}

// A surface with one sharp bend: stiffness 5 N/mm below 2.3 mm, 60 above, joined over 0.1 mm.
double bent(double x) { return 5 * x + 55 * 0.1 * std::log1p(std::exp((x - 2.3) / 0.1)); }

}  // namespace

TEST_CASE("a noiseless table whose surface bends once: the rows go to the bend, and the estimated error falls with each") {
  const Grid g = Grid::make(0.0, 4.0, 12);
  const EverettTable t = table_of(g, bent);
  DesignOptions o;
  o.budget_s = 400;
  o.max_rows = 4;
  const Design d = design_rows(t, {}, o);
  REQUIRE(d.rows.size() == 4);
  CHECK(d.rms_before_N > 0);
  double before = d.rms_before_N;
  for (const DesignRow& r : d.rows) {
    CAPTURE(r.alpha_mm);
    CAPTURE(r.why);
    // At the bend or a band beside it (the divided differences reach one node further): a uniform
    // schedule would spread them over the 12 bands of 0..4 mm.
    CHECK(std::fabs(r.alpha_mm - 2.3) < 0.7);
    CHECK(r.why.find("bends") != std::string::npos);
    CHECK(r.rms_after_N < before);
    CHECK(r.seconds == doctest::Approx(2 * r.alpha_mm / o.ramp_mm_s + o.settle_s));
    before = r.rms_after_N;
  }
  CHECK(d.nodes.size() == static_cast<std::size_t>(g.n + 1 + 4));
  CHECK(std::is_sorted(d.nodes.begin(), d.nodes.end()));
  // A table without a bend (a straight spring) has nothing to gain: no row.
  const Design flat = design_rows(table_of(g, [](double x) { return 40 * x; }), {}, o);
  CHECK(flat.rows.empty());
  CHECK(flat.stopped.rfind("gain", 0) == 0);
}

TEST_CASE("the same uncertainty everywhere: the cheaper rows (lower tops, shorter ramps) come first") {
  const Grid g = Grid::make(0.0, 4.0, 8);
  const EverettTable t = table_of(g, [](double x) { return 40 * x; });
  const std::vector<double> sigma(g.cell_count(), 0.3);
  DesignOptions o;
  o.budget_s = 1e5;
  o.max_rows = 3;
  const Design d = design_rows(t, sigma, o);
  CAPTURE(d.stopped);
  REQUIRE(d.rows.size() == 3);
  CHECK(d.rows[0].alpha_mm == doctest::Approx(0.25));  // the lowest band's middle
  CHECK(d.rows[0].why.find("uncertainty") != std::string::npos);
  CHECK(d.rows[0].seconds < d.rows[2].seconds + 1e-9);
}

TEST_CASE("a design stops on each of its rules and says which") {
  const Grid g = Grid::make(0.0, 4.0, 12);
  const EverettTable t = table_of(g, bent);
  DesignOptions o;
  o.budget_s = 1e6;
  o.min_gain = 0;
  // target: just below the error as it is, one or two rows reach it
  o.target_rms_N = design_rows(t, {}, DesignOptions{}).rms_before_N * 0.8;
  Design d = design_rows(t, {}, o);
  CHECK(d.stopped.rfind("target", 0) == 0);
  CHECK(!d.rows.empty());
  CHECK(d.rows.back().rms_after_N <= o.target_rms_N);
  // budget: room for two rows up to the bend and back
  o.target_rms_N = 0;
  o.budget_s = 2 * (2 * 2.5 / o.ramp_mm_s + o.settle_s);
  d = design_rows(t, {}, o);
  CHECK(d.stopped.rfind("budget", 0) == 0);
  CHECK(d.seconds <= o.budget_s);
  CHECK(d.rows.size() >= 1);
  // gain: a row must remove half of what is left
  o.budget_s = 1e6;
  o.min_gain = 0.5;
  d = design_rows(t, {}, o);
  CHECK(d.stopped.rfind("gain", 0) == 0);
}

TEST_CASE("bad designs are refused with the option named") {
  const Grid g = Grid::make(0.0, 4.0, 12);
  const EverettTable t = table_of(g, bent);
  DesignOptions o;
  o.budget_s = 1;  // below one row: the cheapest goes up to 0.167 mm and back at 0.18 mm/s, 3.9 s
  CHECK_THROWS_WITH((void)design_rows(t, {}, o), doctest::Contains("budget_s"));
  o = DesignOptions{};
  o.target_rms_N = -1;
  CHECK_THROWS_WITH((void)design_rows(t, {}, o), doctest::Contains("target_rms_N"));
  o = DesignOptions{};
  o.ramp_mm_s = 0;
  CHECK_THROWS_WITH((void)design_rows(t, {}, o), doctest::Contains("ramp_mm_s"));
  const std::vector<double> short_sigma(5, 0.1);
  CHECK_THROWS_WITH((void)design_rows(t, short_sigma, DesignOptions{}), doctest::Contains("σ"));
}
