// Acceptance cases of the identification methods beyond the paper (issue: 5a-5d).
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/inverse.hpp"
#include "hystlab/models/lsq_fit.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/representation_checks.hpp"
#include "hystlab/models/sine_fit.hpp"
#include "hystlab/models/sma_calibration.hpp"
#include "test_support.hpp"

using namespace hystlab::models;

using hystlab::test::run_model;

TEST_CASE("5a: constrained least squares recovers a Preisach table from arbitrary noisy data") {
  std::mt19937_64 rng(31);
  const Grid g = Grid::make(0.0, 4.0, 8);
  const double sigma = 0.05;
  const auto [truth, x, y] = hystlab::test::noisy_relay_record(rng, g, sigma);

  const LsqFitResult fit = fit_preisach_lsq(x, y, g);
  CHECK(fit.lambda > 0.0);
  CHECK(fit.rms_residual == doctest::Approx(sigma).epsilon(0.3));  // fits down to the noise, not below
  for (double w : fit.cell_weight) CHECK(w >= 0.0);                // F monotone
  for (int i = 0; i <= g.n; ++i) CHECK(fit.table.node_value(i, i) == 0.0);
  double worst = 0.0, scale = truth.node_value(g.n, 0);
  for (std::size_t k = 0; k < truth.values().size(); ++k) worst = std::max(worst, std::fabs(fit.table.values()[k] - truth.values()[k]));
  CHECK(worst < 0.05 * scale);
  CHECK(std::fabs(fit.force_offset) < 0.1);
  std::size_t with_sigma = 0;
  for (std::size_t c = 0; c < fit.cell_sigma.size(); ++c) {
    CHECK(std::isfinite(fit.cell_sigma[c]));
    with_sigma += fit.cell_sigma[c] > 0.0 ? 1U : 0U;
  }
  CHECK(with_sigma + fit.cells_at_bound == g.cell_count());
  CHECK(fit.effective_parameters > 1.0);
  CHECK(fit.effective_parameters < static_cast<double>(g.cell_count()) + 1.0);
}

namespace {
EverettTable table_from_cells(const Grid& g, const std::vector<double>& w, double offset) {
  std::vector<double> v(g.node_count(), 0.0);
  for (int i = 1; i <= g.n; ++i)
    for (int j = 0; j < i; ++j) {
      double s = 0.0;
      for (int p = j + 1; p <= i; ++p)
        for (int q = j + 1; q <= p; ++q) s += w[Grid::cell_index(p, q)];
      v[Grid::index(i, j)] = s;
    }
  return EverettTable(g, v, offset);
}
double rms_of(const EverettTable& t, const std::vector<double>& x, const std::vector<double>& y) {
  PreisachModel pm(t);
  double ss = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) ss += std::pow(pm.step(x[k]) - y[k], 2);
  return std::sqrt(ss / static_cast<double>(x.size()));
}
}  // namespace

TEST_CASE("5a: on data no non-negative Preisach model fits, the constrained optimum is found") {
  // The simplified SMA model needs negative cells near the diagonal; with w >= 0 the fit must
  // hold some cells at the bound, beat the clipped FOT table, and admit no improving feasible move.
  std::mt19937_64 rng(5);
  const Grid g = Grid::make(0.0, 4.0, 6);
  SimplifiedSmaModel sma(table1_parameters());
  const auto x = hystlab::test::random_ramps(rng, 0.0, 4.0, 60, 0.02);
  const auto y = run_model(sma, x);
  const LsqFitResult fit = fit_preisach_lsq(x, y, g, LsqFitOptions{1e-12, 0});
  for (double w : fit.cell_weight) CHECK(w >= 0.0);
  CHECK(fit.cells_at_bound > 0);
  std::vector<double> clipped;
  for (const CellWeight& c : cell_weights(identify_virtual(sma, g))) clipped.push_back(std::max(0.0, c.weight));
  CHECK(fit.rms_residual < rms_of(table_from_cells(g, clipped, 0.0), x, y));
  const double best = rms_of(table_from_cells(g, fit.cell_weight, fit.force_offset), x, y);
  CHECK(best == doctest::Approx(fit.rms_residual).epsilon(1e-9));
  std::uniform_int_distribution<std::size_t> cell(0, fit.cell_weight.size() - 1);
  std::uniform_real_distribution<double> delta(-0.5, 0.5);
  for (int trial = 0; trial < 200; ++trial) {
    auto w = fit.cell_weight;
    const std::size_t c = cell(rng);
    w[c] = std::max(0.0, w[c] + delta(rng));
    CAPTURE(trial);
    CHECK(rms_of(table_from_cells(g, w, fit.force_offset), x, y) >= best - 1e-9);
  }
}

TEST_CASE("5a: bad fit input is refused") {
  const Grid g = Grid::make(0.0, 4.0, 8);
  const std::vector<double> few(10, 1.0);
  CHECK_THROWS_WITH((void)fit_preisach_lsq(few, few, g), doctest::Contains("too few"));
  CHECK_THROWS_WITH((void)fit_preisach_lsq(few, std::vector<double>(9), g), doctest::Contains("differ in length"));
  CHECK_THROWS_WITH((void)fit_preisach_lsq(few, few, Grid::make(0, 4, 60)), doctest::Contains("at most 48"));
}

TEST_CASE("5b: calibration recovers Table 1 within 2% from a loop with 1% force noise") {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    SimplifiedSmaModel m(table1_parameters());
    const auto x = ramp_through({0.0, 4.0, 0.0}, 0.004);
    auto y = run_model(m, x);
    const double sigma = 0.01 * 157.5;  // 1 % of the force range
    std::normal_distribution<double> noise(0.0, sigma);
    for (double& v : y) v += noise(rng);
    const SmaCalibration cal = calibrate_simplified_sma(x, y, SmaCalibrationOptions{5.7, 25.0, 200});
    const SmaParameters t1 = table1_parameters(), p = cal.parameters;
    const std::pair<double, double> pairs[] = {{p.KA, t1.KA},   {p.KM, t1.KM},   {p.dtr_max, t1.dtr_max}, {p.Mf0, t1.Mf0},
                                               {p.Ms0, t1.Ms0}, {p.As0, t1.As0}, {p.Af0, t1.Af0}};
    for (const auto& pair : pairs) {
      const double got = pair.first, want = pair.second;
      CAPTURE(got);
      CAPTURE(want);
      CHECK(std::fabs(got - want) <= 0.02 * std::fabs(want));
    }
    CHECK(cal.rms_residual == doctest::Approx(sigma).epsilon(0.15));
  }
}

TEST_CASE("5b: a loop that never transforms is refused with a reason") {
  SimplifiedSmaModel m(table1_parameters());
  const auto x = ramp_through({0.0, 0.8, 0.0}, 0.01);  // stays on the austenite line
  const auto y = run_model(m, x);
  CHECK_THROWS_WITH((void)calibrate_simplified_sma(x, y), doctest::Contains("calibrate"));
}

TEST_CASE("5c: inverse model gives the displacement for a requested force, from the current memory") {
  std::mt19937_64 rng(12);
  const Grid g = Grid::make(0.0, 4.0, 12);
  SimplifiedSmaModel sma(table1_parameters());
  PreisachModel pm(identify_virtual(sma, g));
  const auto path = hystlab::test::random_ramps(rng, 0.0, 4.0, 10, 0.05);
  for (double x : path) pm.step(x);
  for (double target : {30.0, 60.0, 100.0, 45.0, 20.0}) {
    CAPTURE(target);
    const InverseResult r = invert(pm, target, g.lo, g.hi, 1e-10);
    if (r.error) {
      CHECK(r.error == std::errc::result_out_of_range);
      continue;
    }
    CHECK(pm.step(r.displacement) == doctest::Approx(target).epsilon(1e-6));
  }
  const InverseResult far = invert(pm, 1e6, g.lo, g.hi);
  CHECK(far.error == std::errc::result_out_of_range);
}

TEST_CASE("5d: wiping-out and congruency hold for a Preisach model and are measured off for the SMA model") {
  std::mt19937_64 rng(77);
  // Nested minor loops with repeated extrema from different histories.
  std::vector<double> tp{0.0, 3.6, 1.0, 3.0, 1.5, 2.5, 1.5, 3.0, 0.4, 3.8, 1.5, 2.5, 1.5, 3.9, 0.0};
  const auto x = ramp_through(tp, 0.01);
  const Grid g = Grid::make(0.0, 4.0, 12);
  PreisachModel pm(RelayGrid(hystlab::test::random_relays(rng, g)).everett_table(g));
  const auto yp = run_model(pm, x);
  const RepresentationReport rp = check_representation(x, yp);
  CHECK(rp.wiping_out.events >= 3);
  CHECK(rp.congruency.compared_pairs >= 1);
  CHECK(rp.wiping_out.max_deviation_norm < 1e-6);
  CHECK(rp.congruency.max_deviation_norm < 1e-6);

  SimplifiedSmaModel sma(table1_parameters());
  const auto ys = run_model(sma, x);
  const RepresentationReport rs = check_representation(x, ys);
  CHECK(rs.congruency.compared_pairs >= 1);
  CHECK(rs.congruency.max_deviation_norm > 1e-4);  // the simplified model's minor loops are not congruent
}

TEST_CASE("sine fit: amplitude and phase of a noisy sine over whole cycles") {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<double> t, y;
  for (int k = 0; k < 2000; ++k) {
    t.push_back(k * 1e-3);
    y.push_back(0.3 + 1.5 * std::sin(2 * std::numbers::pi * 7.0 * t.back() + 0.4) + noise(rng));
  }
  const hystlab::models::SineFit f = hystlab::models::fit_sine(t, y, 7.0);
  REQUIRE(f.ok);
  CHECK(f.amplitude == doctest::Approx(1.5).epsilon(1e-3));
  CHECK(f.phase_rad == doctest::Approx(0.4).epsilon(1e-2));
  CHECK(f.offset == doctest::Approx(0.3).epsilon(1e-2));
  CHECK(f.rms_residual == doctest::Approx(0.01).epsilon(0.1));
  CHECK_FALSE(hystlab::models::fit_sine(std::span(t).first(3), std::span(y).first(3), 7.0).ok);
}
