#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "hystlab/models/everett_table.hpp"
#include "test_support.hpp"

using namespace hystlab::models;

namespace {
EverettTable random_table(std::mt19937_64& rng, const Grid& g) { return hystlab::models::RelayGrid(hystlab::test::random_relays(rng, g)).everett_table(g); }
}  // namespace

TEST_CASE("grid: node count matches the paper's 90 points plus the trivial one") {
  CHECK(Grid::make(0, 4, 4).node_count() == 15);
  CHECK(Grid::make(0, 4, 8).node_count() == 45);
  CHECK(Grid::make(0, 4, 12).node_count() == 91);
  CHECK(Grid::make(0, 4, 12).node(12) == 4.0);
  CHECK_THROWS_WITH(Grid::make(4, 0, 12), doctest::Contains("greater than its start"));
  CHECK_THROWS_WITH(Grid::make(0, 4, 0), doctest::Contains("subdivisions"));
}

TEST_CASE("everett table: interpolation reproduces nodes and is continuous") {
  std::mt19937_64 rng(7);
  const Grid g = Grid::make(0.5, 4.0, 7);
  const EverettTable t = random_table(rng, g);
  for (int i = 0; i <= g.n; ++i)
    for (int j = 0; j <= i; ++j) CHECK(t.value(g.node(i), g.node(j)) == doctest::Approx(t.node_value(i, j)).epsilon(1e-12));
  // Continuity across every cell edge: tiny moves give tiny changes.
  std::uniform_real_distribution<double> u(g.lo, g.hi);
  double max_jump = 0.0;
  for (int k = 0; k < 20000; ++k) {
    double a = u(rng), b = u(rng);
    if (b > a) std::swap(a, b);
    const double e = 1e-9;
    max_jump = std::max(max_jump, std::fabs(t.value(a + e, b) - t.value(a, b)));
    max_jump = std::max(max_jump, std::fabs(t.value(a, b - e) - t.value(a, b)));
  }
  CHECK(max_jump < 1e-6);
}

TEST_CASE("everett table: triangle rule is linear through its three corners (Eq. 9)") {
  const Grid g = Grid::make(0, 2, 2);
  // F(1,0)=3, F(2,0)=5, F(2,1)=2
  const EverettTable t(g, {0, 3, 0, 5, 2, 0});
  // Triangle of column 2: corners (1,1)=0, (2,1)=2, (2,2)=0; midpoint of (2,1)-(2,2) edge:
  CHECK(t.value(2.0, 1.5) == doctest::Approx(1.0));
  // centroid of the triangle (5/3, 4/3): mean of the corners
  CHECK(t.value(5.0 / 3.0, 4.0 / 3.0) == doctest::Approx(2.0 / 3.0));
  // Rectangle (Eq. 8) centre: mean of F(1,0)=3, F(1,1)=0, F(2,0)=5, F(2,1)=2
  CHECK(t.value(1.5, 0.5) == doctest::Approx(2.5));
  // Clamping: outside the range reads the edge; b above a reads the diagonal.
  CHECK(t.value(9.0, -3.0) == doctest::Approx(5.0));
  CHECK(t.value(1.0, 1.7) == doctest::Approx(0.0));
}

TEST_CASE("everett table: stencil equals value") {
  std::mt19937_64 rng(11);
  const Grid g = Grid::make(0, 3, 5);
  const EverettTable t = random_table(rng, g);
  std::uniform_real_distribution<double> u(-0.2, 3.2);
  for (int k = 0; k < 2000; ++k) {
    const double a = u(rng), b = u(rng);
    CAPTURE(a);
    CAPTURE(b);
    const InterpolationStencil st = t.stencil(a, b);
    double v = 0.0;
    for (int s = 0; s < st.size; ++s) v += st.weight[static_cast<std::size_t>(s)] * t.values()[st.node[static_cast<std::size_t>(s)]];
    CHECK(v == doctest::Approx(t.value(a, b)).epsilon(1e-12));
  }
}

TEST_CASE("everett table: bad values are refused with a reason") {
  const Grid g = Grid::make(0, 2, 2);
  CHECK_THROWS_WITH(EverettTable(g, {0, 1, 0}), doctest::Contains("expected 6 values"));
  CHECK_THROWS_WITH(EverettTable(g, {0, 1, 0.5, 2, 1, 0}), doctest::Contains("must be 0"));
  CHECK_THROWS_WITH(EverettTable(g, {0, NAN, 0, 2, 1, 0}), doctest::Contains("not finite"));
}
