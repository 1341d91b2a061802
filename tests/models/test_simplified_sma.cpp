#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "hystlab/models/formats.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "test_support.hpp"

using namespace hystlab::models;

TEST_CASE("simplified SMA: Table 1 transition points (MODELS.md §2, with the erratum)") {
  const SmaTransitions t = transitions(table1_parameters());
  CHECK(t.Ms.displacement == doctest::Approx(1.0118).epsilon(1e-4));
  CHECK(t.Ms.force == doctest::Approx(40.47).epsilon(1e-4));
  CHECK(t.Mf.displacement == doctest::Approx(3.4174).epsilon(1e-4));
  CHECK(t.Mf.force == doctest::Approx(70.11).epsilon(1e-4));
  CHECK(t.As.displacement == doctest::Approx(3.2198).epsilon(1e-4));
  CHECK(t.As.force == doctest::Approx(40.47).epsilon(1e-4));
  CHECK(t.Af.displacement == doctest::Approx(0.4988).epsilon(1e-3));
  CHECK(t.Af.force == doctest::Approx(19.95).epsilon(1e-4));
}

TEST_CASE("simplified SMA: major loop corners and 157.5 N at 4 mm") {
  SimplifiedSmaModel m(table1_parameters());
  const SmaTransitions& t = m.transition_points();
  CHECK(m.step(0.5) == doctest::Approx(20.0));  // austenite line, KA = 40
  CHECK(m.step(t.Ms.displacement) == doctest::Approx(t.Ms.force));
  CHECK(m.step(2.0) == doctest::Approx(t.Ms.force + t.forward_slope() * (2.0 - t.Ms.displacement)));
  CHECK(m.step(t.Mf.displacement) == doctest::Approx(t.Mf.force));
  CHECK(m.step(4.0) == doctest::Approx(157.5));
  CHECK(m.martensite_fraction() == 1.0);
  CHECK(m.step(t.As.displacement) == doctest::Approx(t.As.force));  // unloading on the martensite line
  CHECK(m.step(2.0) == doctest::Approx(t.Af.force + t.reverse_slope() * (2.0 - t.Af.displacement)));
  CHECK(m.step(t.Af.displacement) == doctest::Approx(t.Af.force));
  CHECK(m.martensite_fraction() == 0.0);
  CHECK(m.step(0.0) == doctest::Approx(0.0));
  CHECK(m.step(-0.1) == doctest::Approx(-4.0));  // austenite line continued
}

TEST_CASE("simplified SMA: minor loop leaves the transformation on the Reuss elastic line") {
  SimplifiedSmaModel m(table1_parameters());
  m.step(2.5);
  const double xi = m.martensite_fraction();
  CHECK(xi > 0.0);
  CHECK(xi < 1.0);
  const double f = m.output();
  const double k = m.elastic_stiffness(xi);
  CHECK(k > 40.0);
  CHECK(k < 150.0);
  CHECK(m.step(2.4) == doctest::Approx(f - 0.1 * k));
  CHECK(m.martensite_fraction() == xi);
  CHECK(m.step(2.5) == doctest::Approx(f));  // reloading returns to the reversal point
  m.step(2.6);
  CHECK(m.martensite_fraction() > xi);  // and the forward transformation resumes
}

TEST_CASE("simplified SMA: force is continuous along random paths (randomized)") {
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    SmaParameters p = table1_parameters();
    if (seed > 4) {  // perturbed parameters too
      std::uniform_real_distribution<double> s(0.9, 1.1);
      p.KA *= s(rng);
      p.KM *= s(rng);
      p.dtr_max *= s(rng);
    }
    SimplifiedSmaModel m(p);
    const auto in = hystlab::test::random_ramps(rng, -0.2, 4.5, 80, 1e-3);
    double prev_x = 0.0, prev_f = 0.0, worst = 0.0;
    for (double x : in) {
      const double f = m.step(x);
      REQUIRE(std::isfinite(f));
      CHECK(m.input() == x);
      const double xi = m.martensite_fraction();
      CHECK(xi >= 0.0);
      CHECK(xi <= 1.0);
      worst = std::max(worst, std::fabs(f - prev_f) / std::max(1e-12, std::fabs(x - prev_x)));
      prev_x = x;
      prev_f = f;
    }
    CHECK(worst <= std::max(p.KA, p.KM) * (1 + 1e-6));  // no jumps: slope never above the stiffest line
  }
}

TEST_CASE("simplified SMA: a step is the same as many small steps (rate independence)") {
  SimplifiedSmaModel coarse(table1_parameters()), fine(table1_parameters());
  for (double target : {3.0, 1.2, 2.7, 0.3, 4.0, 2.0, 2.9, 0.0}) {
    coarse.step(target);
    const double from = fine.input();
    for (int k = 1; k <= 1000; ++k) fine.step(from + (target - from) * k / 1000.0);
    CAPTURE(target);
    CHECK(coarse.output() == doctest::Approx(fine.output()).epsilon(1e-9));
  }
}

TEST_CASE("simplified SMA: parameters file round trip and errors naming the field") {
  const auto j = params_to_json(table1_parameters(), "Table 1");
  const SmaParameters p = params_from_json(j.dump());
  CHECK(p.KA == 40.0);
  CHECK(p.Af0 == 21.5);
  auto bad = j;
  bad["KM_N_per_mm"] = -1;
  CHECK_THROWS_WITH((void)params_from_json(bad.dump()), doctest::Contains("KM_N_per_mm"));
  bad = j;
  bad.erase("T_degC");
  CHECK_THROWS_WITH((void)params_from_json(bad.dump()), doctest::Contains("missing field 'T_degC'"));
  bad = j;
  bad["dtr_max_mm"] = 0.1;
  CHECK_THROWS_WITH((void)params_from_json(bad.dump()), doctest::Contains("dtr_max_mm"));
  CHECK_THROWS_WITH((void)params_from_json("{not json"), doctest::Contains("not valid JSON"));
}
