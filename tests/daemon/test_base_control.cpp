// The closed-loop base amplitude's pure core: bands, the drive's correction against a table
// whose response changes with frequency, and the drive's cap.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "hystlab/daemon/base_control.hpp"
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
  CHECK_FALSE(p.window(0.80));  // the first window is never enough
  CHECK(p.window(0.81));        // within 2 % of the one before: done
  CHECK(p.frequency() == 18.5);
  // A ringing isolator: its windows never agree; after 8 the check goes on, and says so.
  for (int k = 0; k < 7; ++k) CHECK_FALSE(p.window(k % 2 ? 0.3 : 0.6));
  CHECK(p.window(0.45));
  CHECK(p.frequency() == 30);
  p.restart_frequency();  // a pause: the frequency's windows count afresh
  CHECK_FALSE(p.window(1.2));
  CHECK(p.window(1.2));
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
