// What a sweep is read for: harmonic fits (THD), the resonance (frequency, peak, half-power
// bandwidth, Q) against the analytic linear curve, the jumps between sweeping up and down, and
// the default simulated isolator's physics (drivers/sim/shaker_sim.hpp) through SdofSystem: its
// resonance at a small amplitude is its linearised natural frequency, and a large amplitude
// makes up and down differ where a small one does not.
#include <doctest/doctest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <random>

#include "hystlab/models/sdof.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/models/sine_fit.hpp"
#include "hystlab/models/sweep_analysis.hpp"

using namespace hystlab::models;

namespace {
constexpr double kPi = std::numbers::pi;

// The simulator's default isolator: 13 kg on 4 springs of Table 1 carrying the weight, 58 N·s/m.
SdofSystem default_isolator() {
  const SmaParameters p = table1_parameters();
  std::vector<SdofSpring> s;
  for (int i = 0; i < 4; ++i) s.push_back({std::make_unique<SimplifiedSmaModel>(p), std::max(p.KA, p.KM)});
  SdofOptions o;
  o.mass_kg = 13.0;
  o.preload_mm = 13.0 * 9.81 / 4 / p.KA;  // on the austenite line (below Ms)
  o.damping_N_s_per_mm = 0.058;
  return SdofSystem(std::move(s), o);
}

std::vector<SweepPoint> sweep(SdofSystem& sys, double amplitude, const std::vector<double>& f) {
  std::vector<SweepPoint> out;
  for (const double fk : f) {
    const SteadyResponse r = steady_response(sys, amplitude, fk, std::max(30, static_cast<int>(3 * fk)), 10);
    out.push_back({fk, r.ratio, r.phase_rad});
  }
  return out;
}

std::vector<double> log_steps(double a, double b, int n) {
  std::vector<double> f;
  for (int k = 0; k < n; ++k) f.push_back(a * std::pow(b / a, k / double(n - 1)));
  return f;
}
}  // namespace

TEST_CASE("harmonic fit: amplitude, phase and THD of a distorted sine, on a phase that moves (a chirp)") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const double a1 = 0.1 + u(rng), a3 = 0.3 * u(rng) * a1, p1 = 2 * kPi * u(rng), c = u(rng) - 0.5;
    CAPTURE(trial);
    std::vector<double> phase, y;
    double ph = 0, f = 10;
    for (int k = 0; k < 2000; ++k) {  // 2 kHz, the frequency rising 10 -> 14 Hz
      ph += 2 * kPi * f / 2000;
      f += 0.002;
      phase.push_back(ph);
      y.push_back(c + a1 * std::sin(ph + p1) + a3 * std::sin(3 * ph));
    }
    const HarmonicFit h = fit_harmonics(phase, y, 5);
    REQUIRE(h.fundamental.ok);
    CHECK(h.fundamental.amplitude == doctest::Approx(a1).epsilon(1e-9));
    CHECK(std::remainder(h.fundamental.phase_rad - p1, 2 * kPi) == doctest::Approx(0).scale(1).epsilon(1e-9));
    CHECK(h.fundamental.offset == doctest::Approx(c).scale(1).epsilon(1e-9));
    CHECK(h.thd == doctest::Approx(a3 / a1).scale(1).epsilon(1e-9));
  }
  // Too little of a cycle, or too few samples: no fit.
  std::vector<double> phase{0, 0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.1, 0.11, 0.12}, y(phase.size(), 1.0);
  CHECK_FALSE(fit_harmonics(phase, y, 5).fundamental.ok);
  CHECK_FALSE(fit_harmonics(std::span(phase).first(3), std::span(y).first(3), 1).fundamental.ok);
}

TEST_CASE("resonance: the linear curve's peak, half-power points and Q = 1/(2ζ)") {
  for (const double zeta : {0.02, 0.05, 0.1}) {
    CAPTURE(zeta);
    std::vector<SweepPoint> pts;
    for (const double f : log_steps(5, 80, 200)) pts.push_back({f, linear_transmissibility(f / 20.0, zeta), 0});
    const auto r = find_resonance(pts);
    REQUIRE(r);
    CHECK_FALSE(r->at_edge);
    // Base excitation peaks at r = sqrt(sqrt(1 + 8ζ²) − 1)/(2ζ) (slightly below 1).
    const double rp = std::sqrt(std::sqrt(1 + 8 * zeta * zeta) - 1) / (2 * zeta);
    CHECK(r->frequency_hz == doctest::Approx(20 * rp).epsilon(0.003));
    CHECK(r->peak_ratio == doctest::Approx(linear_transmissibility(rp, zeta)).epsilon(0.02));  // a parabola over 3 points of a sharp peak
    CHECK(r->q == doctest::Approx(1 / (2 * zeta)).epsilon(0.05 + zeta));                       // Q ≈ 1/(2ζ) for light damping
    CHECK(r->resolved);
    // Steps of 30 %: the peak falls between points; the bandwidth is an upper bound, and said to be.
    std::vector<SweepPoint> coarse;
    for (const double f : log_steps(5, 80, 12)) coarse.push_back({f, linear_transmissibility(f / 20.0, zeta), 0});
    const auto c = find_resonance(coarse);
    REQUIRE(c);
    CHECK_FALSE(c->resolved);
    CHECK(c->q < 1 / (2 * zeta));
  }
  // The peak at the sweep's end: said, and no bandwidth.
  std::vector<SweepPoint> rising;
  for (const double f : log_steps(5, 15, 20)) rising.push_back({f, linear_transmissibility(f / 20.0, 0.05), 0});
  const auto edge = find_resonance(rising);
  REQUIRE(edge);
  CHECK(edge->at_edge);
  CHECK(edge->q == 0);
}

TEST_CASE("resonance refinement: steps added around the peak until its half-power band holds the points asked; Q measured, not bounded") {
  // Seeded: a linear isolator anywhere in the sweep, lightly or moderately damped, on a coarse
  // log sweep (the page's and the benchmark's kind); rounds of next_resonance_steps measured on
  // the analytic curve until none is asked.
  std::mt19937 rng(25);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 40; ++trial) {
    const double fn = 9 + 40 * u(rng), zeta = 0.01 + 0.07 * u(rng);
    const int want = 3 + static_cast<int>(5 * u(rng)), coarse_steps = 8 + static_cast<int>(10 * u(rng));
    CAPTURE(trial);
    CAPTURE(fn);
    CAPTURE(zeta);
    CAPTURE(want);
    CAPTURE(coarse_steps);
    std::vector<SweepPoint> pts;
    for (const double f : log_steps(5, 80, coarse_steps)) pts.push_back({f, linear_transmissibility(f / fn, zeta), 0});
    std::vector<double> next;
    int rounds = 0;
    std::size_t added = 0;
    for (;; ++rounds) {
      REQUIRE(rounds < 12);  // it converges, and fast
      next_resonance_steps(pts, want, next);
      if (next.empty()) break;
      for (std::size_t k = 1; k < next.size(); ++k) CHECK(next[k] > next[k - 1]);  // ascending
      for (const double f : next) {
        CHECK(f > 5);
        CHECK(f < 80);
        pts.push_back({f, linear_transmissibility(f / fn, zeta), 0});
      }
      added += next.size();
    }
    CAPTURE(rounds);
    CAPTURE(added);
    const auto r = find_resonance(pts);
    REQUIRE(r);
    CHECK(r->resolved);
    CHECK(points_in_band(*r, pts) >= want);
    CHECK(band_holds(pts, want));
    CHECK(r->q == doctest::Approx(1 / (2 * zeta)).epsilon(0.1));  // within 10 % of 1/(2ζ), as the issue asks on linear springs
    CHECK(added <= static_cast<std::size_t>(4 * (want + 1)));     // a few rounds, not a uniform sweep's hundreds
  }
  // Nothing to add: a peak at the sweep's edge, or a band already holding the points.
  std::vector<SweepPoint> rising, fine;
  for (const double f : log_steps(5, 15, 20)) rising.push_back({f, linear_transmissibility(f / 20.0, 0.05), 0});
  std::vector<double> next;
  next_resonance_steps(rising, 5, next);
  CHECK(next.empty());
  for (const double f : log_steps(5, 80, 400)) fine.push_back({f, linear_transmissibility(f / 20.0, 0.05), 0});
  next_resonance_steps(fine, 5, next);
  CHECK(next.empty());
  const auto band = find_resonance(fine);
  REQUIRE(band);
  next_resonance_steps(fine, 40, next);  // more than it holds: added inside the band, none on a point measured
  CHECK_FALSE(next.empty());
  for (const double f : next) {
    CHECK(f > band->lower_hz);
    CHECK(f < band->upper_hz);
  }
  CHECK(next.size() + static_cast<std::size_t>(points_in_band(*band, fine)) >= 40);
}

TEST_CASE("equivalent damping from the loop: a linear spring-damper's is zeta f/f_n; the SMA isolator's backbone softens and damps more with amplitude") {
  for (const double zeta : {0.01, 0.02, 0.05, 0.2}) {
    for (const double r : {0.3, 0.9, 1.0, 1.1, 2.5}) {
      CAPTURE(zeta);
      CAPTURE(r);
      const std::complex<double> t = std::complex<double>(1, 2 * zeta * r) / std::complex<double>(1 - r * r, 2 * zeta * r);
      CHECK(equivalent_damping(std::abs(t), std::arg(t)) == doctest::Approx(zeta * r).epsilon(1e-9));
    }
  }
  CHECK(std::isnan(equivalent_damping(NAN, 0.1)));
  CHECK(std::isnan(equivalent_damping(0, 0.1)));
  // The simulator's isolator (Table 1 springs) swept up at 0.005 and 0.05 mm: the resonance falls
  // (the springs transform and soften) and the damping at it rises (their hysteresis loop opens).
  std::vector<SweepCurvePoint> all;
  const std::vector<double> f = log_steps(12, 22, 26);
  for (const double a : {0.005, 0.05}) {
    SdofSystem sys = default_isolator();
    for (const SweepPoint& p : sweep(sys, a, f)) all.push_back({a, true, p});
  }
  const SweepReport rep = analyse_sweep(all, 0.1);
  REQUIRE(rep.curves.size() == 2);
  REQUIRE(rep.curves[0].resonance);
  REQUIRE(rep.curves[1].resonance);
  const double f_small = rep.curves[0].resonance->frequency_hz, f_large = rep.curves[1].resonance->frequency_hz;
  const double z_small = rep.curves[0].damping_at_resonance, z_large = rep.curves[1].damping_at_resonance;
  CAPTURE(f_small);
  CAPTURE(f_large);
  CAPTURE(z_small);
  CAPTURE(z_large);
  CHECK(f_small == doctest::Approx(17.7).epsilon(0.03));   // on the austenite line: the linearised 17.7 Hz
  CHECK(z_small == doctest::Approx(0.020).epsilon(0.15));  // the damper's 0.020 alone: the springs elastic
  CHECK(f_large < 0.97 * f_small);
  CHECK(z_large > 1.5 * z_small);
}

TEST_CASE("jumps: the band where up and down differ, and where each direction changes most") {
  std::vector<SweepPoint> up, down;
  for (const double f : log_steps(10, 30, 21)) {
    // A softening isolator: up follows the upper branch to 19 Hz and drops; down jumps up at 16 Hz.
    const double hi = 1 / std::fabs(1 - std::pow(f / 21.0, 2) + 0.05), lo = 1 / std::fabs(1 - std::pow(f / 15.0, 2) + 0.05);
    up.push_back({f, f <= 19 ? std::min(hi, 8.0) : lo, 0});
    down.push_back({f, f >= 16 ? lo : std::min(hi, 8.0), 0});
  }
  const auto j = find_jumps(up, down, 0.10);
  REQUIRE(j.size() == 1);
  CHECK(j[0].lo_hz >= 15.5);
  CHECK(j[0].hi_hz <= 19.5);
  CHECK(j[0].up_jump_hz == doctest::Approx(19.5).epsilon(0.05));
  CHECK(j[0].down_jump_hz == doctest::Approx(15.7).epsilon(0.05));
  CHECK(find_jumps(up, up, 0.10).empty());
}

TEST_CASE("the default simulated isolator: resonance at its linearised frequency when small; up and down differ when large") {
  const double fn = std::sqrt(4 * 40e3 / 13.0) / (2 * kPi), zeta = 58.0 / (2 * std::sqrt(4 * 40e3 * 13.0));
  const std::vector<double> f = log_steps(12, 26, 29);
  SdofSystem small_sys = default_isolator();
  std::vector<double> back(f.rbegin(), f.rend());
  const auto small_up = sweep(small_sys, 0.005, f), small_down = sweep(small_sys, 0.005, back);
  const auto res = find_resonance(small_up);
  REQUIRE(res);
  CAPTURE(res->frequency_hz);
  CHECK(res->frequency_hz == doctest::Approx(fn).epsilon(0.02));
  CHECK(res->q == doctest::Approx(1 / (2 * zeta)).epsilon(0.25));  // 29 steps over the peak of a Q ≈ 25 resonance
  CHECK(find_jumps(small_up, small_down, 0.10).empty());           // elastic: no memory, the directions agree
  // 0.05 mm: at resonance the springs transform (the relative motion passes Ms, 0.21 mm above the
  // preload); the martensite the up sweep leaves behind changes the springs the down sweep sees,
  // so the two directions differ below the resonance, by more than 10 %.
  SdofSystem large_sys = default_isolator();
  const auto large_up = sweep(large_sys, 0.05, f), large_down = sweep(large_sys, 0.05, back);
  const auto jumps = find_jumps(large_up, large_down, 0.10);
  REQUIRE_FALSE(jumps.empty());
  CAPTURE(jumps[0].lo_hz);
  CAPTURE(jumps[0].hi_hz);
  CHECK(jumps[0].hi_hz < fn * 1.1);
  const auto big = find_resonance(large_up);
  REQUIRE(big);
  CHECK(big->peak_ratio < 0.6 * res->peak_ratio);  // the springs' hysteresis damps it
}

TEST_CASE("a sweep's report: curves per amplitude and direction, jumps for the amplitudes swept both ways") {
  std::vector<SweepCurvePoint> pts;
  for (const double a : {0.01, 0.1})
    for (const bool up : {true, false})
      for (const double f : log_steps(5, 80, 12)) pts.push_back({a, up, {f, linear_transmissibility(f / 20.0, a > 0.05 ? 0.2 : 0.05), 0}});
  for (const double f : log_steps(5, 80, 12)) pts.push_back({0.5, true, {f, 1.0, 0}});  // one way only
  const SweepReport r = analyse_sweep(pts, 0.1);
  REQUIRE(r.curves.size() == 5);
  CHECK((r.curves[0].amplitude_mm == 0.01 && r.curves[0].up && !r.curves[1].up));
  CHECK(r.curves[0].resonance.has_value());
  REQUIRE(r.jumps.size() == 2);  // 0.01 and 0.1 (0.5 went up only)
  CHECK(r.jumps[0].jumps.empty());
}
