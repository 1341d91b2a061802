// The closed-loop base amplitude's pure core: bands, the drive's correction against a table
// whose response changes with frequency, and the drive's cap.
#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "hystlab/daemon/base_control.hpp"
#include "sine_change.hpp"
#include "sine_pretest.hpp"

using namespace hystlab::daemon;
using namespace hystlab::domain;

TEST_CASE("base control: converges on the demand (not the tolerance's edge) on any table response, seeded") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 200; ++trial) {
    SineControl c;
    // From the first step's -6 dB to 1 %, the error falls by 1 − gain a window: 12 windows do it
    // from a gain of 0.33 (a slower loop is measured anyway, with a ControlUnreached event).
    c.gain = 0.4 + 0.6 * u(rng);
    const double response = 0.3 + 2 * u(rng), demand = 0.001 + u(rng);  // base per drive, unknown to the loop
    CAPTURE(c.gain);
    CAPTURE(response);
    BaseControl ctl(c);
    double drive = ctl.start(20, demand);
    CHECK(drive == doctest::Approx(c.start_level * demand));  // the first step: from below
    int windows = 0;
    ControlVerdict v;
    do {
      v = ctl.update(20, demand, drive, response * drive);
      drive = v.next_drive_mm;
    } while (!v.converged && ++windows < c.max_windows);
    CHECK(v.converged);
    CHECK(std::fabs(v.error_pct) <= c.converge_pct);
    // Converged, it keeps correcting towards 0 (a controller's loop never stops at a band).
    const ControlVerdict next = ctl.update(20, demand, drive, response * drive);
    CHECK(std::fabs(next.error_pct) <= std::fabs(v.error_pct) + 1e-9);
    // The next step at the same frequency starts at the drive learnt: on the demand at once.
    CHECK(response * ctl.start(20, demand * 2) == doctest::Approx(demand * 2));
  }
}

TEST_CASE("base control: the drive is carried across frequency steps at the response learnt there, seeded") {
  // A table whose response (base per drive) changes smoothly with frequency, as a servo's does
  // with a resonating load: each step starts at the drive interpolated from the frequencies
  // learnt, never at a fraction of it, so a sweep's excitation does not dip and climb at each step.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 50; ++trial) {
    const double f0 = 5 + 20 * u(rng), a = 0.2 + 0.4 * u(rng);
    auto response = [&](double f) { return 0.8 / (1 + a * std::sin(std::log(f / f0))); };
    CAPTURE(f0);
    CAPTURE(a);
    SineControl c;
    BaseControl ctl(c);
    const double demand = 0.05;
    double worst_start = 0;
    for (int step = 0; step < 24; ++step) {  // 5 to 80 Hz, log spaced
      const double f = 5 * std::pow(16.0, step / 23.0);
      double drive = ctl.start(f, demand);
      if (step > 0) worst_start = std::max(worst_start, std::fabs(response(f) * drive / demand - 1));
      ControlVerdict v;
      for (int w = 0; w < c.max_windows && !v.converged; ++w) v = ctl.update(f, demand, drive, response(f) * drive), drive = v.next_drive_mm;
      CHECK(v.converged);
    }
    CHECK(worst_start < 0.25);  // the response changes at most this much from step to step here
    // Between two frequencies learnt: interpolated in log frequency.
    const double mid = 5 * std::pow(16.0, 0.5 / 23.0);
    CHECK(ctl.response_at(mid) == doctest::Approx((ctl.response_at(5) + ctl.response_at(5 * std::pow(16.0, 1 / 23.0))) / 2).epsilon(1e-9));
  }
}

TEST_CASE("base control: bands, the drive's cap, open loop") {
  SineControl c;  // 5 / 10 / 30 %
  BaseControl ctl(c);
  CHECK(ctl.band_of(4.9) == ControlBand::within);
  CHECK(ctl.band_of(-7) == ControlBand::outside);
  CHECK(ctl.band_of(20) == ControlBand::warning);
  CHECK(ctl.band_of(-31) == ControlBand::abort);
  CHECK(ctl.band_of(NAN) == ControlBand::abort);
  // A table that gives a tenth of its drive: the drive stops at 4 × the demand, and says so.
  double drive = ctl.start(10, 1.0);
  ControlVerdict v;
  for (int k = 0; k < 20; ++k) v = ctl.update(10, 1.0, drive, 0.1 * drive), drive = v.next_drive_mm;
  CHECK(drive == doctest::Approx(4.0));
  CHECK(v.limited);
  CHECK(v.band == ControlBand::abort);
  // Open loop: the drive is the demand whatever is measured; the bands are still reported.
  c.closed = false;
  BaseControl open(c);
  CHECK(open.start(10, 0.2) == 0.2);  // no start level either: the drive is the demand
  const ControlVerdict o = open.update(10, 0.2, 0.2, 0.3);
  CHECK(o.next_drive_mm == 0.2);
  CHECK(o.band == ControlBand::abort);
  CHECK(o.error_pct == doctest::Approx(50));
}

TEST_CASE("the loop check: every frequency ascending at a quarter of the smallest level, each done when two windows agree or after 8") {
  SinePlan s;
  s.frequencies_hz = {30, 12, 18.5, 12};
  s.amplitudes_mm = {0.05, 0.02};
  REQUIRE(has_pretest(s));
  SinePretest p(s);
  CHECK(p.frequencies() == 3);  // once each, ascending
  CHECK(p.level() == doctest::Approx(0.005));
  REQUIRE(p.active());
  CHECK(p.frequency() == 12);
  CHECK_FALSE(p.window(0.80, {}));  // the first window is never enough
  CHECK(p.window(0.81, {}));        // within 2 % of the one before: done
  CHECK(p.frequency() == 18.5);
  // A ringing isolator: its windows never agree; after 8 the check goes on, and says so.
  for (int k = 0; k < 7; ++k) CHECK_FALSE(p.window(k % 2 ? 0.3 : 0.6, {}));
  CHECK(p.window(0.45, {}));
  CHECK(p.frequency() == 30);
  p.restart_frequency();  // a pause: the frequency's windows count afresh
  CHECK_FALSE(p.window(1.2, {}));
  CHECK(p.window(1.2, {}));
  CHECK_FALSE(p.active());
  const PretestEvent e = p.summary(3.5);
  CHECK(e.frequencies == 3);
  CHECK(e.windows == 12);
  CHECK(e.unsettled == 1);
  CHECK(e.response_min == doctest::Approx(0.45));
  CHECK(e.response_max == doctest::Approx(1.2));
  // Left out: a continuous sweep, a dwell, a single frequency, open loop, level 0.
  SinePlan one = s;
  one.frequencies_hz = {20};
  CHECK_FALSE(has_pretest(one));
  SinePlan off = s;
  off.control.pretest_level = 0;
  CHECK_FALSE(has_pretest(off));
  SinePlan open = s;
  open.control.closed = false;
  CHECK_FALSE(has_pretest(open));
  SinePlan continuous = s;
  continuous.continuous = true;
  CHECK_FALSE(has_pretest(continuous));
  SinePlan dwell = s;
  dwell.dwell.on = true;
  CHECK_FALSE(has_pretest(dwell));
  CHECK(has_pretest(s));  // and the plan they were made from has one
}

TEST_CASE("the loop check keeps the response it learnt at each planned frequency, for the step changes") {
  SinePlan s;
  s.frequencies_hz = {12, 18.5};
  s.amplitudes_mm = {0.005};
  SinePretest p(s);
  CHECK(p.window(1.0, {2.0, -0.2, -0.1}) == false);
  CHECK(p.window(1.0, {2.1, -0.21, -0.11}));  // the last window's are kept
  CHECK(p.window(0.5, {9.0, -2.7, -2.9}) == false);
  CHECK(p.window(0.5, {9.1, -2.75, -2.95}));
  CHECK(p.phases_at(12).ratio == doctest::Approx(2.1));
  CHECK(p.phases_at(18.5).mass_rad == doctest::Approx(-2.95));
  CHECK_FALSE(p.phases_at(15).known());  // not a planned frequency: nothing learnt there
}

TEST_CASE("a step change: a burst that moves the drive's phase across the resonance, a glide elsewhere, waiting for the base") {
  const double pi = std::numbers::pi;
  // 17 -> 18.5 Hz across a resonance at 17.7: the mass's phase against the base from -28° to
  // -157°, against the drive by 94° less.
  const LearntResponse at17{12.1, -28 * pi / 180, -0.6}, at18{9.4, -157 * pi / 180, -0.6 - 94 * pi / 180};
  SineChange c;
  c.plan(17, 18.5, 100.0, at17, at18, 12, 22);
  REQUIRE(c.kind() == SineChange::Kind::burst);
  CHECK(c.shift_rad() * 180 / pi == doctest::Approx(94));
  const double fb = c.frequency();
  CHECK(fb > 18.5);
  CHECK(fb <= 22);  // within the plan's range: its envelope was checked there
  // The burst lasts until the drive's phase leads a jump's by the shift: (fb - f2)·t = Δ/2π.
  double phase = 100.0;
  int samples = 0;
  while (!c.advance(phase)) phase += 2 * pi * fb * 1e-4, ++samples;
  CHECK_FALSE(c.active());
  CHECK((fb - 18.5) * samples * 1e-4 * 360 == doctest::Approx(94).epsilon(0.01));
  // Down the same way: the phase moved back, below 18.5 Hz.
  c.plan(18.5, 17, 0.0, at18, at17, 12, 22);
  REQUIRE(c.kind() == SineChange::Kind::burst);
  CHECK(c.shift_rad() * 180 / pi == doctest::Approx(-94));
  CHECK(c.frequency() < 17);
  CHECK(c.frequency() >= 12);
  // At the range's edge with no room for the shift: a glide instead.
  c.plan(17, 18.5, 0.0, at17, at18, 12, 18.5);
  CHECK(c.kind() == SineChange::Kind::glide);

  // Both on one side: a glide, its cycles from how much the mass's motion changes (3 a unit).
  const LearntResponse at12{2.1, -0.05, -0.1}, at15{3.6, -0.14, -0.2};
  c.plan(12, 15, 0.0, at12, at15, 12, 22);
  REQUIRE(c.kind() == SineChange::Kind::glide);
  CHECK(c.glide_cycles() == 5);  // |3.6∠-0.14 − 2.1∠-0.05| = 1.51
  c.plan(15, 17, 0.0, at15, at17, 12, 22);
  CHECK(c.glide_cycles() == 24);  // 8.9: the most
  c.plan(15, 17, 0.0, at15, {}, 12, 22);
  CHECK(c.glide_cycles() == 24);  // not learnt there: the most
  c.plan(12, 15, 0.0, at12, at15, 12, 22);
  // Geometric steps, each cycle on only with the base within 3 % (NaN: not measured, on).
  std::vector<double> f{c.frequency()};
  CHECK(c.after_cycle(1.0, 0.0));
  f.push_back(c.frequency());
  CHECK_FALSE(c.after_cycle(-8.0, 0.0));  // the base 8 % low: the same frequency again
  CHECK(c.frequency() == f.back());
  CHECK(c.after_cycle(NAN, 0.0));
  f.push_back(c.frequency());
  CHECK(f[1] / f[0] == doctest::Approx(f[2] / f[1]));
  CHECK(f[0] == doctest::Approx(12 * std::pow(15.0 / 12, 1.0 / 5)));
  // Waiting is bounded: 3 cycles a frequency on average, then on regardless.
  int cycles = 0;
  while (c.active() && cycles < 100) (void)c.after_cycle(50.0, 0.0), ++cycles;
  CHECK_FALSE(c.active());
  CHECK(cycles <= 15);
  // A glide's segments by phase too (no cycle loop): each a cycle from its own start, however
  // late the last one was seen (a glide crossing 1/16 of the sample rate changes ways, review).
  c.plan(12, 15, 0.0, at12, at15, 12, 22);
  CHECK_FALSE(c.advance(6.0));
  CHECK(c.advance(2 * pi + 3.0));  // seen 3 rad late: the next one ends 2π from here
  CHECK_FALSE(c.advance(4 * pi + 2.9));
  CHECK(c.advance(4 * pi + 3.0));
  // Nothing to change.
  c.plan(15, 15, 0.0, at15, at15, 12, 22);
  CHECK_FALSE(c.active());
}
