// Issue 13: the least-squares fit with its prior decided by data, on the matrix-free operator.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "../../models/src/fit_system.hpp"
#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/lsq_fit.hpp"
#include "hystlab/models/preisach_fit.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/preisach_operator.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "test_support.hpp"

using namespace hystlab::models;
using hystlab::test::run_model;

namespace {

// Ramps between random turning points plus small random steps (nested minor loops of every size).
std::vector<double> rough_walk(std::mt19937_64& rng, const Grid& g, int reversals) {
  auto x = hystlab::test::random_ramps(rng, g.lo, g.hi, reversals, g.step() / 3.0);
  std::normal_distribution<double> jitter(0.0, g.step() / 4.0);
  for (std::size_t k = 1; k + 1 < x.size(); k += 3) x[k] += jitter(rng);
  return x;
}

double rms_between(std::span<const double> a, std::span<const double> b, std::size_t from) {
  double ss = 0.0;
  for (std::size_t k = from; k < a.size(); ++k) ss += (a[k] - b[k]) * (a[k] - b[k]);
  return std::sqrt(ss / static_cast<double>(a.size() - from));
}

}  // namespace

namespace {
// A table of random cell masses of both signs (-0.6..1 N) and the given force offset.
EverettTable signed_table(std::mt19937_64& rng, const Grid& g, double offset) {
  std::uniform_real_distribution<double> mass(-0.6, 1.0);
  std::vector<double> w(g.cell_count()), F(g.node_count());
  for (double& e : w) e = mass(rng);
  fit::cells_to_nodes(g, w, F);
  return EverettTable(g, F, offset);
}
}  // namespace

TEST_CASE("the operator is the model's linear map: it matches the row-by-row regressors, and Aᵀ is its adjoint") {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    const Grid g = Grid::make(-1.0, 3.0, 3 + static_cast<int>(seed % 5) * 4);
    auto x = rough_walk(rng, g, 30);
    x.push_back(g.hi + 1.0);  // clamped like the model
    // Odd seeds end at the bottom (every memory term wiped out before the end); even seeds end
    // mid-range, so terms are still alive at the last sample (the difference array's open end).
    x.push_back(seed % 2 == 1 ? g.lo - 1.0 : 0.5 * (g.lo + g.hi));
    const PreisachOperator op(g, x);
    REQUIRE(op.samples() == x.size());
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> v(op.nodes()), out(op.samples()), w(op.samples()), g_out(op.nodes());
    for (double& e : v) e = u(rng);
    for (double& e : w) e = u(rng);
    op.apply(v, out);
    const auto rows = preisach_regressors(g, x);
    double worst = 0.0, scale = 1.0;
    for (std::size_t k = 0; k < rows.size(); ++k) {
      double ref = 0.0;
      for (const RegressorTerm& t : rows[k]) ref += t.weight * v[t.node];
      worst = std::max(worst, std::fabs(ref - out[k]));
      scale = std::max(scale, std::fabs(ref));
    }
    CHECK(worst < 1e-10 * scale);
    op.apply_transpose(w, g_out);
    double lhs = 0.0, rhs = 0.0;
    for (std::size_t k = 0; k < out.size(); ++k) lhs += w[k] * out[k];
    for (std::size_t k = 0; k < v.size(); ++k) rhs += g_out[k] * v[k];
    CHECK(lhs == doctest::Approx(rhs).epsilon(1e-10));
  }
}

TEST_CASE("cell masses to node values: the cumulative sum over the Preisach triangle, and its exact transpose") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n : {1, 2, 5, 11}) {
    CAPTURE(n);
    const Grid g = Grid::make(0.0, 1.0, n);
    std::vector<double> w(g.cell_count()), F(g.node_count()), y(g.node_count()), wt(g.cell_count());
    for (double& e : w) e = u(rng);
    for (double& e : y) e = u(rng);
    fit::cells_to_nodes(g, w, F);
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= i; ++j) {
        double s = 0.0;
        for (int p = j + 1; p <= i; ++p)
          for (int q = j + 1; q <= p; ++q) s += w[Grid::cell_index(p, q)];
        CHECK(F[Grid::index(i, j)] == doctest::Approx(s).epsilon(1e-12));
      }
    for (int i = 0; i <= n; ++i) y[Grid::index(i, i)] = 0.0;  // diagonal nodes are not unknowns
    fit::nodes_to_cells_transpose(g, y, wt);
    double lhs = 0.0, rhs = 0.0;
    for (std::size_t k = 0; k < y.size(); ++k) lhs += y[k] * F[k];
    for (std::size_t k = 0; k < w.size(); ++k) rhs += wt[k] * w[k];
    CHECK(lhs == doctest::Approx(rhs).epsilon(1e-12));
  }
}

TEST_CASE("signed prior: a noiseless record of a table with masses of both signs is reproduced") {
  for (std::uint64_t seed : {11u, 12u, 13u}) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    const Grid g = Grid::make(0.0, 4.0, 10);
    const EverettTable truth = signed_table(rng, g, 2.0);
    PreisachModel gen(truth);
    const auto x = rough_walk(rng, g, 400);
    const auto y = run_model(gen, x);
    const auto [lo, hi] = std::minmax_element(y.begin(), y.end());
    PreisachFitOptions o;
    o.prior = FitPrior::signed_masses;
    o.uncertainty_probes = 0;
    const PreisachFitResult r = fit_preisach(x, y, g, o);
    CAPTURE(r.reason);
    CHECK(r.chosen.prior == FitPrior::signed_masses);
    CHECK(r.chosen.rms_residual < 0.01 * (*hi - *lo));
    CHECK(r.chosen.negative_cells > 0);
    // The table itself, where the record excites it: the mass of the whole triangle, and the
    // major loop's branches.
    PreisachModel a(truth), b(r.chosen.table);
    const auto major = ramp_through({0.0, 4.0, 0.0}, 0.01);
    CHECK(rms_between(run_model(a, major), run_model(b, major), 0) < 0.02 * (*hi - *lo));
  }
}

TEST_CASE("a long record: the prior and λ chosen on it thinned (every turning point kept), the table fitted on every sample") {
  std::mt19937_64 rng(21);
  const Grid g = Grid::make(0.0, 4.0, 6);
  const EverettTable truth = signed_table(rng, g, 0.0);
  PreisachModel gen(truth);
  const auto x = hystlab::test::random_ramps(rng, 0.0, 4.0, 700, 0.003);  // about 450 samples per reversal
  REQUIRE(x.size() > 250000);
  const auto y = run_model(gen, x);
  const auto [lo, hi] = std::minmax_element(y.begin(), y.end());
  PreisachFitOptions o;
  o.prior = FitPrior::signed_masses;
  o.folds = 2;
  o.uncertainty_probes = 2;
  const PreisachFitResult r = fit_preisach(x, y, g, o);
  CAPTURE(r.reason);
  CHECK(r.selection_samples < x.size());
  // Every d-th sample (d the smallest stride bringing it to 200,000 or below) and the turning points.
  const std::size_t d = (x.size() + 199999) / 200000;
  CHECK(r.selection_samples >= x.size() / d);
  CHECK(r.selection_samples <= x.size() / d + 700 + 2);
  // The chosen table's residual is on every sample (run through the model), and small.
  CHECK(r.chosen.rms_residual < 0.01 * (*hi - *lo));
  for (double s : r.chosen.cell_sigma) CHECK(std::isfinite(s));
}

TEST_CASE("acceptance: on the simplified SMA model, auto's error on held-out data is at most the FOT table's") {
  // A random walk over 0..4 mm with 0.2 N of noise. The fit sees the first three quarters; both
  // tables are run over the whole record (so the memory is the specimen's) and scored on the rest.
  std::mt19937_64 rng(2024);
  SimplifiedSmaModel sma(table1_parameters());
  const auto x = hystlab::test::random_ramps(rng, 0.0, 4.0, 500, 0.01);
  const auto truth = run_model(sma, x);
  std::normal_distribution<double> noise(0.0, 0.2);
  auto y = truth;
  for (double& v : y) v += noise(rng);
  const std::size_t train = x.size() * 3 / 4;
  for (int n : {12, 24, 48}) {
    CAPTURE(n);
    const Grid g = Grid::make(0.0, 4.0, n);
    PreisachFitOptions o;
    o.uncertainty_probes = 0;
    o.folds = 3;
    const PreisachFitResult r = fit_preisach(std::span(x).first(train), std::span(y).first(train), g, o);
    CAPTURE(r.reason);
    REQUIRE(r.candidates.size() == 2);
    PreisachModel fitted(r.chosen.table);
    SimplifiedSmaModel source(table1_parameters());
    PreisachModel fot(identify_virtual(source, g));
    const double fit_rms = rms_between(run_model(fitted, x), y, train), fot_rms = rms_between(run_model(fot, x), y, train);
    CAPTURE(fit_rms);
    CAPTURE(fot_rms);
    CHECK(fit_rms <= fot_rms);
    // The specimen needs cells of negative mass: the signed prior wins, on held-out data.
    CHECK(r.chosen.prior == FitPrior::signed_masses);
    CHECK(r.chosen.heldout_rms < r.candidates[1].heldout_rms);
    MESSAGE("n = " << n << ": fit " << fit_rms << " N, FOT " << fot_rms << " N on held-out data; " << r.reason << "; " << r.seconds << " s");
  }
}

TEST_CASE("monotone prior: a record from a table of non-negative masses is recovered within the noise") {
  std::mt19937_64 rng(31);
  const Grid g = Grid::make(0.0, 4.0, 8);
  const double sigma = 0.05;
  const auto [truth, x, y] = hystlab::test::noisy_relay_record(rng, g, sigma);
  PreisachFitOptions o;
  o.prior = FitPrior::monotone;
  const PreisachFitResult r = fit_preisach(x, y, g, o);
  const PriorFit& f = r.chosen;
  CHECK(f.rms_residual == doctest::Approx(sigma).epsilon(0.3));  // down to the noise, not below
  for (double w : f.cell_weight) CHECK(w >= 0.0);
  double worst = 0.0;
  for (std::size_t k = 0; k < truth.values().size(); ++k) worst = std::max(worst, std::fabs(f.table.values()[k] - truth.values()[k]));
  CHECK(worst < 0.05 * truth.node_value(g.n, 0));
  CHECK(std::fabs(f.force_offset) < 0.1);
  // σ: finite everywhere, positive off the bound, and of the size the noise implies.
  std::size_t with_sigma = 0;
  for (std::size_t c = 0; c < f.cell_sigma.size(); ++c) {
    CHECK(std::isfinite(f.cell_sigma[c]));
    with_sigma += f.cell_sigma[c] > 0.0 ? 1U : 0U;
  }
  CHECK(with_sigma + f.cells_at_bound == g.cell_count());
  CHECK(with_sigma > 0);
  // It agrees with the dense active-set fit it replaces, at the same λ.
  const LsqFitResult dense = fit_preisach_lsq(x, y, g, LsqFitOptions{f.lambda, 0});
  CHECK(f.rms_residual == doctest::Approx(dense.rms_residual).epsilon(0.02));
}

TEST_CASE("the monotone solver reaches the constrained optimum: no feasible move improves it") {
  std::mt19937_64 rng(5);
  const Grid g = Grid::make(0.0, 4.0, 6);
  SimplifiedSmaModel sma(table1_parameters());
  const auto x = hystlab::test::random_ramps(rng, 0.0, 4.0, 60, 0.02);
  const auto y = run_model(sma, x);
  PreisachFitOptions o;
  o.prior = FitPrior::monotone;
  o.lambda = 1e-9;
  o.uncertainty_probes = 0;
  o.tolerance = 1e-10;
  const PriorFit f = fit_preisach(x, y, g, o).chosen;
  CHECK(f.converged);
  CHECK(f.cells_at_bound > 0);
  // KKT at the returned point: with g = Q u - b, zero on the free cells and the offset, >= 0 on
  // the cells held at the bound.
  {
    const PreisachOperator op(g, x);
    fit::NormalSystem sys(op, y, std::vector<double>(x.size(), 1.0));
    sys.set_lambda(f.lambda);
    std::vector<double> u = f.cell_weight, grad(sys.size());
    u.push_back(f.force_offset);
    sys.apply(u, grad);
    double bnorm = 0.0;
    for (double b : sys.rhs()) bnorm = std::max(bnorm, std::fabs(b));
    for (std::size_t c = 0; c < sys.size(); ++c) {
      CAPTURE(c);
      const double gc = grad[c] - sys.rhs()[c];
      if (c < sys.cells() && u[c] == 0.0)
        CHECK(gc >= -1e-7 * bnorm);
      else
        CHECK(std::fabs(gc) <= 1e-7 * bnorm);
    }
  }
  auto rms_of = [&](const std::vector<double>& w) {
    std::vector<double> F(g.node_count());
    fit::cells_to_nodes(g, w, F);
    PreisachModel pm(EverettTable(g, F, f.force_offset));
    return rms_between(run_model(pm, x), y, 0);
  };
  const double best = rms_of(f.cell_weight);
  std::uniform_int_distribution<std::size_t> cell(0, f.cell_weight.size() - 1);
  std::uniform_real_distribution<double> delta(-0.5, 0.5);
  for (int trial = 0; trial < 200; ++trial) {
    auto w = f.cell_weight;
    const std::size_t c = cell(rng);
    w[c] = std::max(0.0, w[c] + delta(rng));
    CAPTURE(trial);
    CHECK(rms_of(w) >= best - 1e-6);
  }
}

TEST_CASE("auto with a given λ still compares the priors on held-out blocks") {
  std::mt19937_64 rng(8);
  const Grid g = Grid::make(0.0, 4.0, 6);
  SimplifiedSmaModel sma(table1_parameters());
  const auto x = hystlab::test::random_ramps(rng, 0.0, 4.0, 80, 0.02);
  const auto y = run_model(sma, x);
  PreisachFitOptions o;
  o.lambda = 1e-4;
  o.uncertainty_probes = 0;
  const PreisachFitResult r = fit_preisach(x, y, g, o);
  REQUIRE(r.candidates.size() == 2);
  for (const PriorFit& f : r.candidates) {
    CHECK(f.heldout_rms > 0.0);
    CHECK(f.lambda == 1e-4);
    CHECK(f.cv_lambda.size() == 1);
  }
  CHECK(r.chosen.heldout_rms == std::min(r.candidates[0].heldout_rms, r.candidates[1].heldout_rms));
  CHECK(r.reason.find("lower error on held-out blocks") != std::string::npos);
}

TEST_CASE("bad fit input is refused with the field named") {
  const Grid g = Grid::make(0.0, 4.0, 8);
  const std::vector<double> few(10, 1.0);
  CHECK_THROWS_WITH((void)fit_preisach(few, few, g), doctest::Contains("too few"));
  CHECK_THROWS_WITH((void)fit_preisach(few, std::vector<double>(9), g), doctest::Contains("differ in length"));
  CHECK_THROWS_WITH((void)fit_preisach(few, few, Grid::make(0, 4, 201)), doctest::Contains("at most 200"));
  PreisachFitOptions o;
  o.folds = 1;
  std::vector<double> many(400, 1.0);
  CHECK_THROWS_WITH((void)fit_preisach(many, many, g, o), doctest::Contains("folds"));
  many[17] = std::nan("");
  CHECK_THROWS_WITH((void)fit_preisach(many, many, g), doctest::Contains("sample 17"));
  CHECK_THROWS_WITH((void)fit_prior_from_string("positive"), doctest::Contains("signed, monotone or auto"));
  many[17] = 1.0;
  PreisachFitOptions bad;
  bad.lambda = std::nan("");
  CHECK_THROWS_WITH((void)fit_preisach(many, many, g, bad), doctest::Contains("lambda"));
  bad.lambda = 1e300;
  CHECK_THROWS_WITH((void)fit_preisach(many, many, g, bad), doctest::Contains("lambda"));
  bad.lambda = -1.0;
  bad.tolerance = 0.0;
  CHECK_THROWS_WITH((void)fit_preisach(many, many, g, bad), doctest::Contains("tolerance"));
}
