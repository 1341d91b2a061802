// The simulated rigs' physics, stepped directly (time is passed in, so this runs in no time).
#include <doctest/doctest.h>

#include <cmath>

#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/protocols/signals.hpp"
#include "load_frame_sim.hpp"
#include "shaker_sim.hpp"

using namespace hystlab;
using namespace hystlab::sim;

namespace {
std::unique_ptr<models::HysteresisModel> sma() {
  return std::make_unique<models::SimplifiedSmaModel>(models::table1_parameters());
}
LoadFrameParams quiet() {
  LoadFrameParams p;
  p.noise_N = 0;
  p.corner_width_mm = 0;
  return p;
}
void run(LoadFrameSim& f, double seconds, double dt = 1e-3) {
  for (double t = 0; t < seconds - 1e-12; t += dt) f.step(dt);
}
}  // namespace

TEST_CASE("load frame: the command follows the setpoint at the ramp rate, the actuator lags") {
  LoadFrameSim f(sma(), quiet());
  f.set_commands({3.0, 1.0, true, false, false});
  run(f, 1.0);
  CHECK(f.state().command_mm == doctest::Approx(1.0).epsilon(1e-6));
  CHECK(f.state().displacement_mm < f.state().command_mm);                  // first-order lag
  CHECK(f.state().displacement_mm == doctest::Approx(0.995).epsilon(1e-3));  // 1 mm/s × τ = 5 µm behind
  CHECK(f.state().force_N == doctest::Approx(40.0 * f.state().displacement_mm).epsilon(1e-6));
  CHECK(f.state().sample_counter == 1000);
  f.set_commands({3.0, 1.0, true, true, false});  // hold
  const double held = f.state().command_mm;
  run(f, 0.5);
  CHECK(f.state().command_mm == held);
  CHECK((f.state().status_word & protocols::status::holding) != 0);
}

TEST_CASE("load frame: hard limits and the load cell range trip a safe stop") {
  LoadFrameParams p = quiet();
  p.limit_mm = 2.0;
  LoadFrameSim f(sma(), p);
  f.set_commands({5.0, 50.0, true, false, false});
  run(f, 1.0);
  CHECK(f.state().fault_code == kDisplacementLimit);
  CHECK((f.state().status_word & protocols::status::limit_tripped) != 0);
  CHECK(f.state().displacement_mm < 2.1);  // stopped where it tripped, not at the setpoint
  LoadFrameParams q = quiet();
  q.load_cell_range_N = 30;
  LoadFrameSim g(sma(), q);
  g.set_commands({2.0, 10.0, true, false, false});
  run(g, 1.0);
  CHECK(g.state().fault_code == kForceLimit);
  CHECK(g.state().force_N < 35);
}

TEST_CASE("load frame: e-stop holds, and releasing it resets the trip") {
  LoadFrameSim f(sma(), quiet());
  f.set_commands({2.0, 5.0, true, false, false});
  run(f, 0.2);
  f.set_commands({2.0, 5.0, true, false, true});
  const double at = f.state().displacement_mm;
  run(f, 0.5);
  CHECK(f.state().displacement_mm == doctest::Approx(at).epsilon(0.01));
  CHECK(f.state().fault_code == kEstopPressed);
  f.set_commands({2.0, 5.0, true, false, false});
  f.reset_fault();
  run(f, 0.5);
  CHECK(f.state().fault_code == kNoFault);
  CHECK(f.state().displacement_mm > at + 0.5);
}

TEST_CASE("specimen smoothing: corners rounded, lag bounded, nearly independent of the step size") {
  const double w = 0.05;
  SmoothedSpecimen coarse(sma(), w), fine(sma(), w);
  models::SimplifiedSmaModel sharp(models::table1_parameters());
  double worst = 0, at_ms = 0;
  for (int k = 1; k <= 4000; ++k) {
    const double x = 4.0 * k / 4000.0;
    const double s = coarse.step(x);
    for (int j = 1; j <= 10; ++j) fine.step(4.0 * (k - 1 + j / 10.0) / 4000.0);
    const double f = sharp.step(x);
    worst = std::max(worst, std::fabs(s - f));
    if (std::fabs(x - 1.0118) < 1e-3) at_ms = f - s;
    CHECK(std::fabs(fine.step(x) - s) < 0.16);  // 0.1 % of full scale: the update is first order in the step
  }
  CHECK(at_ms > 0.5);        // the corner at Ms is rounded off
  CHECK(worst < 150 * w * 1.2);  // never more than the stiffest slope times the width
}

TEST_CASE("shaker: rests at its preload, follows the base at low frequency, refuses an unstable step") {
  const models::SimplifiedSmaModel spring(models::table1_parameters());
  ShakerSim s(spring, ShakerParams{});
  CHECK(s.preload_mm() > 0);
  s.step(0.5);
  CHECK(std::fabs(s.state().mass_displacement_mm) < 1e-3);  // static equilibrium
  s.set_drive(2.0, 0.2, true);  // far below resonance (about 50 Hz): transmissibility ≈ 1
  double peak_mass = 0;
  for (int k = 0; k < 2000; ++k) {
    s.step(1e-3);
    if (k > 1000) peak_mass = std::max(peak_mass, std::fabs(s.state().mass_displacement_mm));
  }
  CHECK(peak_mass == doctest::Approx(0.2).epsilon(0.05));
  ShakerParams bad;
  bad.dt_s = 1e-2;
  CHECK_THROWS_WITH(ShakerSim(spring, bad), doctest::Contains("time step too large"));
}
