// Grids of their own (table format version 2): refined where accuracy is needed. The same
// tables as the uniform grid where the nodes coincide, through every format and path.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "hystlab/models/formats.hpp"
#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/preisach_fit.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/models/table_export.hpp"
#include "test_support.hpp"

using namespace hystlab::models;

namespace {
// The uniform grid's nodes, held as a grid of its own: every non-uniform code path, uniform numbers.
Grid explicit_uniform(double lo, double hi, int n) {
  Grid g = Grid::make(lo, hi, n);
  g.positions = std::make_shared<const std::vector<double>>(g.nodes());
  return g;
}

double rms(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (std::size_t k = 0; k < a.size(); ++k) s += (a[k] - b[k]) * (a[k] - b[k]);
  return std::sqrt(s / static_cast<double>(a.size()));
}
}  // namespace

TEST_CASE("grid of its own: nodes, cells, the nearest node; uniform nodes give the uniform grid") {
  const Grid g = Grid::from_nodes({0, 1, 1.5, 1.75, 2, 4});
  CHECK_FALSE(g.uniform());
  CHECK(g.n == 5);
  CHECK(g.lo == 0);
  CHECK(g.hi == 4);
  CHECK(g.step() == 0.25);  // the smallest cell
  double f = 0;
  CHECK(g.cell_of(1.6, f) == 3);
  CHECK(f == doctest::Approx(0.4));
  CHECK(g.cell_of(4.0, f) == 5);
  CHECK(f == 1.0);
  CHECK(g.cell_of(-1.0, f) == 1);
  CHECK(f == 0.0);
  CHECK(g.node_near(1.74, 0.02) == 3);
  CHECK(g.node_near(3.0, 0.1) == -1);
  CHECK(g.node_near(4.0, 1e-9) == 5);
  CHECK(Grid::from_nodes({0, 1, 2, 3, 4}).uniform());
  CHECK_THROWS_WITH(Grid::from_nodes({0, 1, 1}), doctest::Contains("node 2"));
  CHECK_THROWS_WITH(Grid::from_nodes({0}), doctest::Contains("2 to 2001"));
  // Refined around a preload: half the cells in the window, the rest on both sides.
  const Grid r = Grid::refined(0, 4, 8, 2.0, 1.0);
  CHECK(r.n == 8);
  int inside = 0;
  for (int i = 1; i <= r.n; ++i) inside += r.node(i - 1) >= 1.5 - 1e-12 && r.node(i) <= 2.5 + 1e-12;
  CHECK(inside == 4);
  CHECK(r.node(0) == 0);
  CHECK(r.node(8) == 4);
}

TEST_CASE("grid of its own: with the uniform grid's nodes, the same forces as the uniform code, seeded records") {
  SimplifiedSmaModel sma(table1_parameters());
  for (int n : {3, 8, 17}) {
    CAPTURE(n);
    const EverettTable u = identify_virtual(sma, Grid::make(0, 4, n));
    const EverettTable e = identify_virtual(sma, explicit_uniform(0, 4, n));
    for (std::size_t k = 0; k < u.values().size(); ++k) CHECK(e.values()[k] == u.values()[k]);
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      CAPTURE(seed);
      std::mt19937_64 rng(seed);
      const auto x = hystlab::test::random_ramps(rng, -0.2, 4.2, 40, 0.013);
      PreisachModel a(u), b(e);
      const auto fa = hystlab::test::run_model(a, x), fb = hystlab::test::run_model(b, x);
      for (std::size_t k = 0; k < x.size(); ++k) REQUIRE(fb[k] == doctest::Approx(fa[k]).epsilon(1e-12));
    }
  }
}

TEST_CASE("grid of its own: where nodes coincide with the uniform grid's, the table's values are the same") {
  SimplifiedSmaModel sma(table1_parameters());
  const Grid u = Grid::make(0, 4, 8);
  std::vector<double> moved = u.nodes();
  moved[3] = 1.3;  // one node moved (1.5 -> 1.3): every node pair without it is shared
  const EverettTable a = identify_virtual(sma, u), b = identify_virtual(sma, Grid::from_nodes(moved));
  for (int i = 0; i <= 8; ++i)
    for (int j = 0; j <= i; ++j) {
      if (i == 3 || j == 3) continue;
      CAPTURE(i);
      CAPTURE(j);
      CHECK(b.node_value(i, j) == a.node_value(i, j));
    }
}

TEST_CASE("grid of its own: round trips through JSON v2, CSV, MATLAB and the C header; uniform stays v1") {
  SimplifiedSmaModel sma(table1_parameters());
  const Grid g = Grid::refined(0, 4, 8, 2.0, 1.0);
  const EverettTable t = identify_virtual(sma, g);
  const TableProvenance p{"test", "virtual-fot", "2026-11-25T00:00:00Z", "", {}};
  const auto j = table_to_json(t, p);
  CHECK(j["version"] == kTableVersionNodes);
  const TableDocument back = table_from_json(j.dump());
  CHECK(back.table.grid().same_nodes(g));
  CHECK_FALSE(back.table.grid().uniform());
  for (std::size_t k = 0; k < t.values().size(); ++k) CHECK(back.table.values()[k] == t.values()[k]);
  CHECK(table_to_json(identify_virtual(sma, Grid::make(0, 4, 8)), p)["version"] == kTableVersion);
  const std::string csv = table_to_csv(t, p);
  CHECK(csv.find("v2") != std::string::npos);
  CHECK(csv.find(",1.75,") != std::string::npos);  // the refined node, as an α or β position
  const std::string m = table_to_matlab(t, p);
  CHECK(m.find("T.nodes = [0 0.75 1.5 1.75 2 2.25 2.5 3.25 4];") != std::string::npos);
  const std::string h = table_to_c_header(t, p, "refined");
  CHECK(h.find("REFINED_NODES_MM[REFINED_N + 1] = {0, 0.75, 1.5, 1.75, 2, 2.25, 2.5, 3.25, 4};") != std::string::npos);
  // Version 2 with nodes that are not increasing, or that miss the range: refused, named.
  auto bad = j;
  bad["nodes_mm"][4] = 1.0;
  CHECK_THROWS_WITH((void)table_from_json(bad.dump()), doctest::Contains("nodes_mm[4]"));
  bad = j;
  bad["nodes_mm"][8] = 3.9;
  CHECK_THROWS_WITH((void)table_from_json(bad.dump()), doctest::Contains("from range_mm[0] to range_mm[1]"));
}

TEST_CASE("grid of its own: refined around a preload, the same node count gives a smaller error on small loops about it") {
  SimplifiedSmaModel sma(table1_parameters());
  // Loaded to 2.3 mm, then loops of ±0.3 mm about a 2 mm preload.
  std::vector<double> turns{0.0, 2.3};
  for (int c = 0; c < 5; ++c) turns.insert(turns.end(), {1.7, 2.3});
  const auto x = ramp_through(turns, 0.005);
  const auto truth = hystlab::test::run_model(sma, x);
  for (int n : {8, 12}) {
    CAPTURE(n);
    PreisachModel uniform(identify_virtual(sma, Grid::make(0, 4, n)));
    PreisachModel refined(identify_virtual(sma, Grid::refined(0, 4, n, 2.0, 1.0)));
    const double eu = rms(hystlab::test::run_model(uniform, x), truth), er = rms(hystlab::test::run_model(refined, x), truth);
    MESSAGE("n = " << n << ": uniform " << eu << " N, refined " << er << " N RMS on loops about the preload");
    CHECK(er < 0.75 * eu);
  }
}

TEST_CASE("grid of its own: measured FOT nodes on it give it back; the least-squares fit runs on it") {
  SimplifiedSmaModel sma(table1_parameters());
  const Grid g = Grid::from_nodes({0, 0.8, 1.6, 2.0, 2.4, 3.2, 4.0});
  const VirtualCampaign vc = run_virtual_fot(sma, g);
  const FotIdentification id = identify_from_nodes(vc.nodes, 0.0, vc.force_at_min);
  CHECK(id.table.grid().same_nodes(g, 1e-12));
  const EverettTable direct = identify_virtual(sma, g);
  for (std::size_t k = 0; k < direct.values().size(); ++k) CHECK(id.table.values()[k] == doctest::Approx(direct.values()[k]).epsilon(1e-12));
  // The fit on the same grid, from a noiseless record of that table: the record reproduced.
  std::mt19937_64 rng(5);
  const auto x = hystlab::test::random_ramps(rng, 0, 4, 60, 0.01);
  PreisachModel m(direct);
  const auto y = hystlab::test::run_model(m, x);
  PreisachFitOptions o;
  o.prior = FitPrior::signed_masses;
  o.lambda = 1e-7;
  o.uncertainty_probes = 0;
  const PreisachFitResult fit = fit_preisach(x, y, g, o);
  CHECK(fit.chosen.table.grid().same_nodes(g));
  double range = 0;
  for (double v : y) range = std::max(range, std::fabs(v));
  CHECK(fit.chosen.rms_residual < 0.01 * range);
}
