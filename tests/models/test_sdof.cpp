// The base-excited isolator: against the analytic linear solution, the energy balance, the
// convergence as the step shrinks, and its refusals.
#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/linear_spring.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/sdof.hpp"
#include "hystlab/models/simplified_sma.hpp"

using namespace hystlab::models;

namespace {
std::vector<SdofSpring> linear(double k, int n) {
  std::vector<SdofSpring> s;
  for (int i = 0; i < n; ++i) s.push_back({std::make_unique<LinearSpring>(k), k});
  return s;
}
std::vector<SdofSpring> sma(int n) {
  std::vector<SdofSpring> s;
  const SmaParameters p = table1_parameters();
  for (int i = 0; i < n; ++i) s.push_back({std::make_unique<SimplifiedSmaModel>(p), std::max(p.KA, p.KM)});
  return s;
}
// 2 kg on 2 Table 1 tubes preloaded to 3 mm, mid-plateau.
SdofSystem sma_isolator(double dt, double damping) {
  SdofOptions o;
  o.mass_kg = 2.0;
  o.preload_mm = 3.0;
  o.dt_s = dt;
  o.damping_N_s_per_mm = damping;
  return SdofSystem(sma(2), o);
}
// m = 1 kg on 2 springs of 5 N/mm: ω_n = sqrt(1000·10/1) = 100 rad/s.
SdofOptions linear_options(double zeta, double dt = 1e-4) {
  SdofOptions o;
  o.mass_kg = 1.0;
  o.preload_mm = 2.0;
  o.damping_N_s_per_mm = 2 * zeta * o.mass_kg * 100.0 / 1000.0;
  o.dt_s = dt;
  return o;
}
}  // namespace

TEST_CASE("sdof: with linear springs the transmissibility is the analytic curve") {
  const double fn = 100.0 / (2 * std::numbers::pi);
  for (double zeta : {0.05, 0.2}) {
    for (double r : {0.3, 0.8, 1.0, 1.5, 3.0}) {
      SdofSystem sys(linear(5.0, 2), linear_options(zeta));
      const double settle_s = 8.0 / (zeta * 100.0);  // transients decay as exp(−ζω_n t)
      const int settle = static_cast<int>(std::ceil(settle_s * r * fn));
      const SteadyResponse s = steady_response(sys, 0.05, r * fn, settle, 10);
      CAPTURE(zeta);
      CAPTURE(r);
      CHECK(s.ratio == doctest::Approx(linear_transmissibility(r, zeta)).epsilon(0.005));
      CHECK(sys.lift_off_steps() == 0);
    }
  }
}

TEST_CASE("sdof: energy balance: input work = damper + spring work + kinetic + gravity") {
  SUBCASE("linear spring and damper: the spring work is its potential energy") {
    SdofSystem sys(linear(5.0, 2), linear_options(0.1));
    sys.set_base(0.2, 12.0);
    sys.run_for(1.3);
    const SdofEnergy& e = sys.energy();
    CAPTURE(e.input);
    CAPTURE(e.residual());
    CHECK(std::fabs(e.residual()) < 1e-4 * (std::fabs(e.input) + e.damper));
    const double d0 = 2.0, d1 = sys.state().delta;
    CHECK(e.spring == doctest::Approx(2 * 0.5 * 5.0 * (d1 * d1 - d0 * d0)).epsilon(1e-6));
    CHECK(e.damper > 0);
  }
  SUBCASE("SMA springs driven through their transformation: the balance closes within the integration error") {
    auto run = [](double dt) {
      SdofSystem sys = sma_isolator(dt, 0.02);
      sys.set_base(0.5, 35.0);  // near resonance: the tubes transform every cycle
      sys.run_for(2.0);
      return sys.energy();
    };
    const SdofEnergy coarse = run(1e-4), fine = run(2.5e-5);
    CAPTURE(coarse.residual());
    CAPTURE(fine.residual());
    CHECK(fine.input > 100);                // N·mm fed in by the base
    CHECK(fine.spring > 0.3 * fine.input);  // most of it went into the springs' hysteresis
    CHECK(std::fabs(fine.residual()) < 1e-3 * fine.input);
    CHECK(std::fabs(fine.residual()) < std::fabs(coarse.residual()));  // it is integration error: it shrinks with the step
  }
}

TEST_CASE("sdof: the response converges as the step shrinks") {
  auto ratio = [](double dt) {
    SdofSystem sys = sma_isolator(dt, 0.01);
    return steady_response(sys, 0.5, 25.0, 40, 10).ratio;
  };
  const double r1 = ratio(4e-4), r2 = ratio(2e-4), r3 = ratio(1e-4), r4 = ratio(5e-5);
  CAPTURE(r1);
  CAPTURE(r2);
  CAPTURE(r3);
  CAPTURE(r4);
  CHECK(std::fabs(r3 - r4) < std::fabs(r1 - r4));
  CHECK(std::fabs(r3 - r4) < 0.01 * r4);
}

TEST_CASE("sdof: bad inputs are refused with a clear error") {
  SdofOptions o = linear_options(0.1, 0.02);  // ω_max = 100 rad/s: dt·ω_max = 2
  CHECK_THROWS_WITH_AS(SdofSystem(linear(5.0, 2), o), doctest::Contains("unstable"), std::invalid_argument);
  o = linear_options(0.1);
  o.mass_kg = -1;
  CHECK_THROWS_WITH_AS(SdofSystem(linear(5.0, 2), o), doctest::Contains("mass_kg"), std::invalid_argument);
  o = linear_options(0.1);
  o.damping_N_s_per_mm = -0.1;
  CHECK_THROWS_WITH_AS(SdofSystem(linear(5.0, 2), o), doctest::Contains("damping"), std::invalid_argument);
  CHECK_THROWS_WITH_AS(SdofSystem({}, linear_options(0.1)), doctest::Contains("spring"), std::invalid_argument);
  CHECK_THROWS_AS(LinearSpring(-3), std::invalid_argument);
  SdofSystem sys(linear(5.0, 2), linear_options(0.1));
  CHECK_THROWS_WITH_AS((void)steady_response(sys, 0.1, 2000.0, 1, 1), doctest::Contains("too fast"), std::invalid_argument);
}

TEST_CASE("sdof: a base motion beyond the preload lifts the mass off the springs, and it is counted") {
  SdofSystem sys(linear(5.0, 2), linear_options(0.02));
  (void)steady_response(sys, 1.5, 100.0 / (2 * std::numbers::pi), 20, 5);  // resonance, amplitude near the preload
  CHECK(sys.lift_off_steps() > 0);
}

// Springs of one table are evaluated once and counted (SdofSystem::group_tables): the same
// motion, to rounding, as the same springs each stepped (separate copies of the table, which
// are not grouped), with a base that lifts the mass off them now and then.
TEST_CASE("sdof: springs of one table evaluated once move the mass as springs each stepped") {
  SimplifiedSmaModel virgin(table1_parameters());
  const EverettTable t = identify_virtual(virgin, Grid::make(0.0, 5.0, 16));
  const auto shared = std::make_shared<const EverettTable>(t);
  std::vector<SdofSpring> one_table, copies;
  for (int k = 0; k < 3; ++k) {
    one_table.push_back({std::make_unique<PreisachModel>(shared), max_stiffness(t)});
    copies.push_back({std::make_unique<PreisachModel>(EverettTable(t)), max_stiffness(t)});
  }
  SdofOptions o;
  o.mass_kg = 3.0;
  o.preload_mm = 3.0;
  o.damping_N_s_per_mm = 0.01;
  SdofSystem grouped(std::move(one_table), o), each(std::move(copies), o);
  for (SdofSystem* s : {&grouped, &each}) s->set_base(4.0, 80.0);  // above resonance: δ from about -1 to 7 mm
  for (int k = 0; k < 20000; ++k) {
    grouped.step(), each.step();
    CAPTURE(k);
    REQUIRE(grouped.state().x == doctest::Approx(each.state().x).epsilon(1e-9));
  }
  CHECK(grouped.lift_off_steps() == each.lift_off_steps());
  CHECK(each.lift_off_steps() > 0);
  CHECK(grouped.energy().spring == doctest::Approx(each.energy().spring).epsilon(1e-9));
}
