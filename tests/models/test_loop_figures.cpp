// Loop figures (models/loop_figures): against hand-computed values on piecewise-linear loops, and
// cycle finding on records of known structure.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/loop_figures.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/models/sma_calibration.hpp"
#include "test_support.hpp"

namespace {
using hystlab::models::LoopFigures;
struct Pt {
  double x, f;
};

// The polygon's vertices joined by straight lines, `per` samples per side, every vertex a sample.
void trace(const std::vector<Pt>& v, int per, std::vector<double>& x, std::vector<double>& f) {
  if (x.empty()) x.push_back(v[0].x), f.push_back(v[0].f);
  for (std::size_t k = 1; k < v.size(); ++k)
    for (int s = 1; s <= per; ++s) {
      const double w = static_cast<double>(s) / per;
      x.push_back(v[k - 1].x + w * (v[k].x - v[k - 1].x));
      f.push_back(v[k - 1].f + w * (v[k].f - v[k - 1].f));
    }
}

double shoelace(const std::vector<Pt>& v) {  // the enclosed area of a closed polygon (first == last)
  double a = 0;
  for (std::size_t k = 1; k < v.size(); ++k) a += v[k - 1].x * v[k].f - v[k].x * v[k - 1].f;
  return std::fabs(a) / 2;
}

// A superelastic loop by hand: loading KA 40 to Ms (1, 40), plateau to Mf (3, 70), KM 150 to
// (4, 220); unloading KM to As (2.8333, 45), plateau to Af (0.5, 20), KA back to (0, 0).
const double kAsX = 4.0 - 175.0 / 150.0;
const std::vector<Pt> kLoop{{0, 0}, {1, 40}, {3, 70}, {4, 220}, {kAsX, 45}, {0.5, 20}, {0, 0}};
}  // namespace

TEST_CASE("loop figures of a hand-drawn superelastic loop") {
  std::vector<double> x, f;
  trace(kLoop, 500, x, f);
  hystlab::models::LoopOptions o;
  o.plateau_at_mm = {2.0, 9.0};  // 9 mm is outside the loop: not reported
  const auto loops = hystlab::models::find_loops(x, f, o);
  REQUIRE(loops.size() == 1);
  const LoopFigures& L = loops[0];
  CHECK(L.begin == 0);
  CHECK(L.end == x.size() - 1);
  CHECK_FALSE(L.starts_at_max);
  CHECK(L.min_mm == 0.0);
  CHECK(L.max_mm == 4.0);
  CHECK(L.peak_force_N == doctest::Approx(220));
  // The polygon's area by the shoelace formula, 39.583 N·mm (by hand: the loading polygon's area
  // under the curve, 20 + 110 + 145 = 275, less the unloading's, 5 + 76.667 + 153.75 = 235.417).
  const double area = shoelace(kLoop);
  CHECK(area == doctest::Approx(275.0 - (5.0 + (20 + 45) / 2.0 * (kAsX - 0.5) + (45 + 220) / 2.0 * (4 - kAsX))).epsilon(1e-12));
  CHECK(L.energy_Nmm == doctest::Approx(area).epsilon(1e-9));
  CHECK(L.secant_stiffness_N_mm == doctest::Approx(55.0));
  CHECK(L.strain_energy_Nmm == doctest::Approx(0.5 * 55.0 * 4.0));
  CHECK(L.damping_ratio == doctest::Approx(area / (4 * std::numbers::pi * 110.0)));
  CHECK(L.return_N == doctest::Approx(0.0));
  // Unloaded to 1 % of the force range (2.2 N) on the last side, (0.5, 20) to (0, 0): at 0.055 mm.
  CHECK(L.residual_mm == doctest::Approx(0.5 * 2.2 / 20).epsilon(1e-6));
  REQUIRE(L.plateaus.size() == 1);
  CHECK(L.plateaus[0].at_mm == 2.0);
  CHECK(L.plateaus[0].loading_N == doctest::Approx(55.0));  // 40 + 15 * 1
  CHECK(L.plateaus[0].unloading_N == doctest::Approx(20 + 25.0 / (kAsX - 0.5) * 1.5));
  REQUIRE(L.transformation);
  const auto& t = *L.transformation;
  CHECK(t.Ms.displacement == doctest::Approx(1.0).epsilon(1e-3));
  CHECK(t.Ms.force == doctest::Approx(40.0).epsilon(1e-3));
  CHECK(t.Mf.displacement == doctest::Approx(3.0).epsilon(1e-3));
  CHECK(t.Mf.force == doctest::Approx(70.0).epsilon(1e-3));
  CHECK(t.As.displacement == doctest::Approx(kAsX).epsilon(1e-3));
  CHECK(t.As.force == doctest::Approx(45.0).epsilon(1e-3));
  CHECK(t.Af.displacement == doctest::Approx(0.5).epsilon(1e-3));
  CHECK(t.Af.force == doctest::Approx(20.0).epsilon(1e-3));
  CHECK(L.loading->slope_start == doctest::Approx(40).epsilon(1e-3));
  CHECK(L.loading->slope_middle == doctest::Approx(15).epsilon(1e-3));
  CHECK(L.loading->slope_end == doctest::Approx(150).epsilon(1e-3));
}

TEST_CASE("loop figures: random piecewise-linear loops, energy and knees against their corners") {
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    const double top = 2 + 4 * u(rng), ka = 20 + 40 * u(rng), km = 80 + 120 * u(rng);
    const double ms = (0.15 + 0.15 * u(rng)) * top, mf = (0.65 + 0.15 * u(rng)) * top;
    const double fms = ka * ms, fmf = fms + (0.1 + 0.2 * u(rng)) * ka * (mf - ms), ftop = fmf + km * (top - mf);
    const double af = (0.08 + 0.07 * u(rng)) * top, faf = ka * af;
    const double fas = faf + (0.5 + 0.4 * u(rng)) * (fmf - fms), as = top - (ftop - fas) / km;
    CAPTURE(top);
    CAPTURE(as);
    const std::vector<Pt> v{{0, 0}, {ms, fms}, {mf, fmf}, {top, ftop}, {as, fas}, {af, faf}, {0, 0}};
    std::vector<double> x, f;
    trace(v, 300, x, f);
    const auto loops = hystlab::models::find_loops(x, f);
    REQUIRE(loops.size() == 1);
    CHECK(loops[0].energy_Nmm == doctest::Approx(shoelace(v)).epsilon(1e-9));
    CHECK(loops[0].secant_stiffness_N_mm == doctest::Approx(ftop / top));
    REQUIRE(loops[0].transformation);
    const double tol = 1e-3 * top;
    CHECK(std::fabs(loops[0].transformation->Ms.displacement - ms) < tol);
    CHECK(std::fabs(loops[0].transformation->Mf.displacement - mf) < tol);
    CHECK(std::fabs(loops[0].transformation->As.displacement - as) < tol);
    CHECK(std::fabs(loops[0].transformation->Af.displacement - af) < tol);
  }
}

TEST_CASE("loop figures: one load-unload cycle per FOT row, from δmin") {
  std::vector<double> x, f;
  const int n = 8;
  std::vector<Pt> path{{0, 0}};
  for (int i = 1; i <= n; ++i) {
    const double top = 4.0 * i / n;
    path.push_back({top, 30 * top});
    path.push_back({0, 0});
  }
  trace(path, 100, x, f);
  const auto loops = hystlab::models::find_loops(x, f);
  REQUIRE(loops.size() == n);
  for (int i = 0; i < n; ++i) {
    CAPTURE(i);
    CHECK_FALSE(loops[static_cast<std::size_t>(i)].starts_at_max);
    CHECK(loops[static_cast<std::size_t>(i)].min_mm == 0.0);
    CHECK(loops[static_cast<std::size_t>(i)].max_mm == doctest::Approx(4.0 * (i + 1) / n));
  }
}

TEST_CASE("loop figures: a nested loop is counted once and left out of its host") {
  // A Preisach table has return-point memory: a major loop with a minor loop on its unloading
  // branch, its minor loop cut out, is the same closed path as a clean major loop.
  hystlab::models::SimplifiedSmaModel sma(hystlab::models::table1_parameters());
  hystlab::models::PreisachModel m(hystlab::models::identify_virtual(sma, hystlab::models::Grid::make(0, 4, 16)));
  auto ramp = [](std::vector<double>& v, double to) {  // steps of 0.01 mm on both records
    const double from = v.back();
    const int n = static_cast<int>(std::lround(std::fabs(to - from) * 100));
    for (int k = 1; k <= n; ++k) v.push_back(from + (to - from) * k / n);
  };
  std::vector<double> clean{0}, nested{0};
  for (double t : {4.0, 0.0}) ramp(clean, t);
  for (double t : {4.0, 2.0, 3.5, 0.0}) ramp(nested, t);
  m.reset();
  const auto fc = hystlab::test::run_model(m, clean);
  m.reset();
  const auto fn = hystlab::test::run_model(m, nested);
  const auto a = hystlab::models::find_loops(clean, fc), b = hystlab::models::find_loops(nested, fn);
  REQUIRE(a.size() == 1);
  REQUIRE(b.size() == 2);
  CHECK(b[0].min_mm == doctest::Approx(2.0));  // the minor loop closes first
  CHECK(b[0].max_mm == doctest::Approx(3.5));
  CHECK(b[0].energy_Nmm > 0);
  CHECK(b[1].energy_Nmm == doctest::Approx(a[0].energy_Nmm).epsilon(1e-9));
  CHECK(b[1].return_N == doctest::Approx(a[0].return_N));
}

TEST_CASE("loop figures: a dip while loading is a cycle from its maximum") {
  std::vector<double> x{0};
  for (double t : {3.0, 2.0, 4.0, 0.0}) {
    const double from = x.back();
    for (int k = 1; k <= 200; ++k) x.push_back(from + (t - from) * k / 200);
  }
  hystlab::models::SimplifiedSmaModel sma(hystlab::models::table1_parameters());
  const auto f = hystlab::test::run_model(sma, x);
  const auto loops = hystlab::models::find_loops(x, f);
  REQUIRE(loops.size() == 2);
  CHECK(loops[0].starts_at_max);
  CHECK(loops[0].min_mm == doctest::Approx(2.0));
  CHECK(loops[0].max_mm == doctest::Approx(3.0));
  CHECK_FALSE(loops[1].starts_at_max);
  CHECK(loops[1].max_mm == doctest::Approx(4.0));
  CHECK(loops[0].energy_Nmm > 0);
}

TEST_CASE("loop figures: the simplified model's four points, and calibrate starts from them") {
  std::vector<double> x{0};
  for (double t : {4.0, 0.0})
    for (int k = 1; k <= 2000; ++k) x.push_back((t == 4.0 ? 0.0 : 4.0) + (t - (t == 4.0 ? 0.0 : 4.0)) * k / 2000);
  hystlab::models::SimplifiedSmaModel sma(hystlab::models::table1_parameters());
  const auto f = hystlab::test::run_model(sma, x);
  const auto tr = hystlab::models::loop_transformation(x, f);
  REQUIRE(tr);
  const auto truth = sma.transition_points();
  for (const auto& [got, want] : {std::pair{tr->Ms, truth.Ms}, {tr->Mf, truth.Mf}, {tr->As, truth.As}, {tr->Af, truth.Af}}) {
    CHECK(got.displacement == doctest::Approx(want.displacement).epsilon(2e-3));
    CHECK(got.force == doctest::Approx(want.force).epsilon(2e-3));
  }
  const auto c = hystlab::models::calibrate_simplified_sma(x, f);
  const auto guess = hystlab::models::transitions(c.initial_guess);
  CHECK(guess.Ms.force == doctest::Approx(tr->Ms.force).epsilon(1e-9));
  CHECK(guess.Af.force == doctest::Approx(tr->Af.force).epsilon(1e-9));
}

TEST_CASE("loop figures: bad records are refused with the sample named") {
  std::vector<double> x{0, 1, 2, 1, 0}, f{0, 1, NAN, 1, 0};
  CHECK_THROWS_WITH((void)hystlab::models::find_loops(x, f), "loops: sample 2 is not a finite number");
  std::vector<double> g{0, 1};
  CHECK_THROWS_WITH((void)hystlab::models::find_loops(x, g), "loops: displacement and force differ in length");
  const std::vector<double> flat(10, 1.0);
  CHECK(hystlab::models::find_loops(flat, flat).empty());
}

TEST_CASE("residual displacement of a loop with a permanent set, and of a cycle from a maximum") {
  // As the hand-drawn loop, but the unloading reaches no force at 0.3 mm and is pushed below it
  // back to 0 (displacement control): 2.2 N (1 % of 220 N) is crossed on (0.8, 20)-(0.3, 0).
  const std::vector<Pt> set{{0, 0}, {1, 40}, {3, 70}, {4, 220}, {kAsX, 45}, {0.8, 20}, {0.3, 0}, {0, -5}};
  std::vector<double> x, f;
  trace(set, 400, x, f);
  const auto loops = hystlab::models::find_loops(x, f);
  REQUIRE(loops.size() == 1);
  CHECK(loops[0].residual_mm == doctest::Approx(0.3 + 0.5 * 2.2 / 20).epsilon(1e-6));
  // A cycle inside a loading (from a maximum, down and back up) unloads to no start: NaN.
  const auto inner = hystlab::models::loop_figures(std::vector<double>{2, 1, 2}, std::vector<double>{50, 30, 50}, 0, 1, 2);
  CHECK(std::isnan(inner.residual_mm));
}

namespace {
// The sum of squares of the least-squares three-line fit with knots k1 < k2, over the points
// themselves (the library's search uses prefix moments instead: this is its reference).
double direct_hinge_ss(const std::vector<double>& x, const std::vector<double>& y, double k1, double k2) {
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
  Eigen::Vector4d b = Eigen::Vector4d::Zero();
  auto row = [&](double v) { return Eigen::Vector4d(1.0, v, std::max(0.0, v - k1), std::max(0.0, v - k2)); };
  for (std::size_t k = 0; k < x.size(); ++k) A += row(x[k]) * row(x[k]).transpose(), b += row(x[k]) * y[k];
  const Eigen::Vector4d c = A.ldlt().solve(b);
  double ss = 0;
  for (std::size_t k = 0; k < x.size(); ++k) ss += (row(x[k]).dot(c) - y[k]) * (row(x[k]).dot(c) - y[k]);
  return ss;
}
}  // namespace

TEST_CASE("branch knees: the search's knots fit at least as well as every pair of its coarse grid, on seeded noisy three-line branches") {
  std::mt19937 rng(20261129);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 12; ++trial) {
    const double lo = 10 * u(rng) - 5, span = 0.5 + 20 * u(rng);
    const double k1 = lo + span * (0.1 + 0.3 * u(rng)), k2 = lo + span * (0.6 + 0.3 * u(rng));
    const double s0 = 20 + 80 * u(rng), s1 = 5 * u(rng) - 2, s2 = 20 + 80 * u(rng), noise = 2 * u(rng);
    const std::size_t n = 50 + static_cast<std::size_t>(700 * u(rng));  // below and above the 400 taken
    CAPTURE(trial);
    CAPTURE(n);
    std::vector<double> x(n), y(n);
    std::normal_distribution<double> e(0, noise);
    for (std::size_t k = 0; k < n; ++k) {
      x[k] = lo + span * u(rng);  // any order of displacement
      y[k] = s0 * (x[k] - lo) + (s1 - s0) * std::max(0.0, x[k] - k1) + (s2 - s1) * std::max(0.0, x[k] - k2) + e(rng);
    }
    const auto b = hystlab::models::fit_branch_knees(x, y);
    REQUIRE(b.has_value());
    // The points the library takes: every stride-th, as documented (kMaxKneePoints).
    const std::size_t stride = std::max<std::size_t>(1, (n + hystlab::models::kMaxKneePoints - 1) / hystlab::models::kMaxKneePoints);
    std::vector<double> tx, ty;
    for (std::size_t k = 0; k < n; k += stride) tx.push_back(x[k]), ty.push_back(y[k]);
    const double found = direct_hinge_ss(tx, ty, b->lower_mm, b->upper_mm);
    CHECK(b->rms_N == doctest::Approx(std::sqrt(found / static_cast<double>(tx.size()))).epsilon(1e-9));
    const double step = (b->hi_mm - b->lo_mm) / 40;
    double grid_best = 1e300;
    for (int i = 1; i < 40; ++i)
      for (int j = i + 1; j < 40; ++j) grid_best = std::min(grid_best, direct_hinge_ss(tx, ty, b->lo_mm + step * i, b->lo_mm + step * j));
    CHECK(found <= grid_best * (1 + 1e-9) + 1e-9);
    CHECK(std::fabs(b->lower_mm - k1) < 0.05 * span);
    CHECK(std::fabs(b->upper_mm - k2) < 0.05 * span);
  }
}
