#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "hystlab/models/accuracy.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/relay_grid.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "test_support.hpp"

using namespace hystlab::models;

TEST_CASE("identification: the identified table reproduces every FOT node force of its data") {
  for (int n : {4, 8, 12}) {
    CAPTURE(n);
    const Grid g = Grid::make(0.0, 4.0, n);
    SimplifiedSmaModel sma(table1_parameters());
    const VirtualCampaign c = run_virtual_fot(sma, g);
    CHECK(c.nodes.size() == static_cast<std::size_t>(n * (n + 1) / 2));
    const FotIdentification id = identify_from_nodes(g, c.nodes, 0.0, c.force_at_min);
    // Drive the identified model through the same input and compare each node force.
    PreisachModel pm(id.table);
    pm.step(g.lo);
    std::size_t k = 0;
    for (int i = 1; i <= n; ++i) {
      for (int r = 1; r <= i; ++r) pm.step(g.node(r));
      CHECK(pm.output() == doctest::Approx(c.nodes[k].force_alpha).epsilon(1e-12));
      for (int j = i - 1; j >= 0; --j, ++k) CHECK(pm.step(g.node(j)) == doctest::Approx(c.nodes[k].force_alpha_beta).epsilon(1e-12));
    }
  }
}

TEST_CASE("identification: error against the simplified model falls as n grows (paper §3.3)") {
  std::mt19937_64 rng(2024);
  const auto input = hystlab::test::random_ramps(rng, 0.0, 4.0, 40, 0.01);
  SimplifiedSmaModel ref(table1_parameters());
  std::vector<double> yref(input.size());
  ref.evaluate(input, yref);
  double prev = 1e300;
  for (int n : {4, 8, 12, 24, 48}) {
    CAPTURE(n);
    SimplifiedSmaModel sma(table1_parameters());
    PreisachModel pm(identify_virtual(sma, Grid::make(0.0, 4.0, n)));
    std::vector<double> y(input.size());
    pm.evaluate(input, y);
    const AccuracyReport acc = compare(input, yref, y);
    CHECK(acc.overall.rms < prev);
    prev = acc.overall.rms;
    CHECK(acc.ascending.count + acc.descending.count == input.size());
  }
  CHECK(prev < 1.0);  // n = 48: RMS error below 1 N on a 157 N range
}

TEST_CASE("identification: noisy repeated descents give a drift figure and no false violations") {
  // A true Preisach material (non-negative weights); the SMA model's own table has negative cells.
  std::mt19937_64 rng(42);
  const Grid g = Grid::make(0.0, 4.0, 6);
  RelayGrid material(hystlab::test::random_relays(rng, g));
  const auto clean = run_virtual_fot(material, g).nodes;
  std::normal_distribution<double> noise(0.0, 0.02);
  std::vector<FotNode> nodes;
  for (int rep = 0; rep < 3; ++rep)
    for (const FotNode& c : clean) {
      FotNode n = c;
      n.force_alpha += noise(rng);
      n.force_alpha_beta += noise(rng);
      nodes.push_back(n);
    }
  const FotIdentification id = identify_from_nodes(nodes);
  CHECK(id.table.grid().n == 6);
  CHECK(id.drift.repeated_rows == 6);
  CHECK(id.drift.pooled_std == doctest::Approx(0.02).epsilon(0.5));
  CHECK(id.drift.max_spread > 0.0);
  CHECK(id.violations.empty());
  for (int i = 0; i <= g.n; ++i) CHECK(id.table.node_value(i, i) == 0.0);  // F(α,α) = 0 enforced
}

TEST_CASE("identification: the simplified SMA model is not a Preisach material: its table has negative cells") {
  SimplifiedSmaModel sma(table1_parameters());
  const FotIdentification id = identify_from_nodes(run_virtual_fot(sma, Grid::make(0.0, 4.0, 6)).nodes, 0.0);
  CHECK_FALSE(id.violations.empty());
  for (const CellWeight& c : id.violations) CHECK(c.weight < 0.0);
}

TEST_CASE("identification: a node that breaks monotonicity beyond noise is reported") {
  const Grid g = Grid::make(0.0, 3.0, 3);
  SimplifiedSmaModel sma(table1_parameters());
  auto nodes = run_virtual_fot(sma, g).nodes;
  for (FotNode& n : nodes)
    if (n.alpha == 2.0 && n.beta == 1.0) n.force_alpha_beta -= 25.0;  // F(2,1) far too large
  const FotIdentification id = identify_from_nodes(nodes, 0.1);
  REQUIRE_FALSE(id.violations.empty());
  bool names_cell = false;
  for (const CellWeight& c : id.violations) names_cell |= (c.p == 3 && c.q == 2) || (c.p == 2 && c.q == 1);
  CHECK(names_cell);
}

TEST_CASE("identification: incomplete or off-grid data is refused with the node named") {
  const Grid g = Grid::make(0.0, 4.0, 4);
  SimplifiedSmaModel sma(table1_parameters());
  auto nodes = run_virtual_fot(sma, g).nodes;
  auto missing = nodes;
  missing.erase(missing.begin() + 3);
  CHECK_THROWS_WITH((void)identify_from_nodes(missing), doctest::Contains("missing node"));
  auto skewed = nodes;
  for (FotNode& n : skewed)
    if (n.alpha == 2.0) n.alpha = 2.2;
  // The α values make a grid of its own (0, 1, 2.2, 3, 4): the β = 2 nodes are then off it.
  CHECK_THROWS_WITH((void)identify_from_nodes(skewed), doctest::Contains("(alpha 3 mm, beta 2 mm): beta is not on a grid node"));
  auto above = nodes;
  above[0].beta = above[0].alpha + 1.0;
  CHECK_THROWS_WITH((void)identify_from_nodes(above), doctest::Contains("beta above alpha"));
}

TEST_CASE("online builder: coverage grows node by node and the partial table is always usable") {
  const Grid g = Grid::make(0.0, 4.0, 5);
  SimplifiedSmaModel sma(table1_parameters());
  const auto c = run_virtual_fot(sma, g);
  OnlineTableBuilder b(g);
  CHECK(b.identified_nodes() == 0);
  CHECK(b.required_nodes() == 15);
  std::size_t added = 0;
  for (const FotNode& n : c.nodes) {
    REQUIRE_FALSE(b.add(n));
    ++added;
    CHECK(b.identified_nodes() == added);
    const EverettTable partial = b.table();
    for (const CellWeight& w : cell_weights(partial)) {
      // unmeasured cells carry zero weight
      if (!b.cell_identified(w.p, w.q)) CHECK(w.weight == doctest::Approx(0.0).epsilon(1e-12));
    }
    PreisachModel pm(partial);
    CHECK(std::isfinite(pm.step(3.0)));
  }
  CHECK(b.complete());
  CHECK(b.cell_identified(5, 1));
  const EverettTable full = b.table();
  const EverettTable offline = identify_from_nodes(g, c.nodes).table;
  for (std::size_t k = 0; k < full.values().size(); ++k) CHECK(full.values()[k] == offline.values()[k]);
  CHECK(b.add(FotNode{2.1, 0.0, 1, 0}) == FotError::off_grid_alpha);
  CHECK(b.add(FotNode{2.4, 3.2, 1, 0}) == FotError::beta_above_alpha);
  CHECK(b.add(FotNode{NAN, 0.0, 1, 0}) == FotError::not_finite);
}

TEST_CASE("table format: round trip and errors naming the field") {
  SimplifiedSmaModel sma(table1_parameters());
  const EverettTable t = identify_virtual(sma, Grid::make(0.0, 4.0, 4));
  const auto j = table_to_json(t, TableProvenance{"Table 1", "virtual-fot", "2026-11-23T00:00:00Z", "test", {}});
  const TableDocument d = table_from_json(j.dump());
  REQUIRE(d.table.values().size() == t.values().size());
  for (std::size_t k = 0; k < t.values().size(); ++k) CHECK(d.table.values()[k] == t.values()[k]);
  CHECK(d.provenance.method == "virtual-fot");
  auto bad = j;
  bad["version"] = 3;
  CHECK_THROWS_WITH((void)table_from_json(bad.dump()), doctest::Contains("unknown format version 3"));
  bad = j;
  bad["version"] = 2;
  bad.erase("nodes_mm");
  CHECK_THROWS_WITH((void)table_from_json(bad.dump()), doctest::Contains("version 2 needs 'nodes_mm'"));
  bad = j;
  bad["nodes_mm"][2] = 2.2;  // increasing, but not the uniform grid: only version 2 may say so
  CHECK_THROWS_WITH((void)table_from_json(bad.dump()), doctest::Contains("a grid of its own is version 2"));
  bad = j;
  bad["nodes_mm"][2] = 0.5;
  CHECK_THROWS_WITH((void)table_from_json(bad.dump()), doctest::Contains("non-monotone grid"));
  bad = j;
  bad["rows"][3][1] = "x";
  CHECK_THROWS_WITH((void)table_from_json(bad.dump()), doctest::Contains("rows[3][1]"));
  CHECK_THROWS_AS((void)table_from_json(R"({"format": "hystlab-everett-table", "version": 1, "range_mm": [0, 1e999]})"), FormatError);
  bad = j;
  bad["units"] = {{"displacement", 5}};
  CHECK_THROWS_AS((void)table_from_json(bad.dump()), FormatError);
  bad = j;
  bad["format"] = "other";
  CHECK_THROWS_WITH((void)table_from_json(bad.dump()), doctest::Contains("'format'"));
}

TEST_CASE("accuracy: measures per branch and loop energy") {
  const std::vector<double> x{0, 1, 2, 1, 0};
  const std::vector<double> ref{0, 1, 2, 1.5, 0};
  const std::vector<double> mod{0, 1, 2.5, 1.5, 0};
  const AccuracyReport r = compare(x, ref, mod);
  CHECK(r.overall.max_abs == doctest::Approx(0.5));
  CHECK(r.ascending.max_abs == doctest::Approx(0.5));
  CHECK(r.descending.max_abs == doctest::Approx(0.0));
  CHECK(r.ascending.count == 3);
  CHECK(r.reference_range == doctest::Approx(2.0));
  REQUIRE(r.energy_reference.has_value());
  CHECK(*r.energy_reference == doctest::Approx(-0.5));  // ∮ f dδ: loading 2, unloading -2.5
  CHECK_THROWS((void)compare(x, ref, std::vector<double>{1.0}));
}
