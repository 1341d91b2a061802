// The closed-loop base amplitude's pure core: bands, the drive's correction against a table
// whose response changes with frequency, and the drive's cap.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "hystlab/daemon/base_control.hpp"

using namespace hystlab::daemon;
using namespace hystlab::domain;

TEST_CASE("base control: reaches the demand on any table response within its windows, seeded") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 200; ++trial) {
    SineControl c;
    c.gain = 0.3 + 0.7 * u(rng);
    const double response = 0.3 + 2 * u(rng), demand = 0.001 + u(rng);  // base per drive, unknown to the loop
    CAPTURE(c.gain);
    CAPTURE(response);
    BaseControl ctl(c);
    double drive = ctl.start(demand);
    int windows = 0;
    ControlVerdict v;
    do {
      v = ctl.update(demand, drive, response * drive);
      drive = v.next_drive_mm;
    } while (v.band != ControlBand::within && ++windows < c.max_windows);
    CHECK(v.band == ControlBand::within);
    CHECK(std::fabs(v.error_pct) <= c.tolerance_pct);
    // The next step starts from what was learnt, below its target by the start level.
    CHECK(response * ctl.start(demand * 2) == doctest::Approx(c.start_level * demand * 2));
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
  double drive = ctl.start(1.0);
  ControlVerdict v;
  for (int k = 0; k < 20; ++k) v = ctl.update(1.0, drive, 0.1 * drive), drive = v.next_drive_mm;
  CHECK(drive == doctest::Approx(4.0));
  CHECK(v.limited);
  CHECK(v.band == ControlBand::abort);
  // Open loop: the drive is the demand whatever is measured; the bands are still reported.
  c.closed = false;
  BaseControl open(c);
  CHECK(open.start(0.2) == 0.2);  // no start level either: the drive is the demand
  const ControlVerdict o = open.update(0.2, 0.2, 0.3);
  CHECK(o.next_drive_mm == 0.2);
  CHECK(o.band == ControlBand::abort);
  CHECK(o.error_pct == doctest::Approx(50));
}
