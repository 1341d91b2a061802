// The simulated rigs' physics, stepped directly (time is passed in, so this runs in no time).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/models/sine_fit.hpp"
#include "hystlab/protocols/default_maps.hpp"
#include "hystlab/protocols/register_map.hpp"
#include "hystlab/protocols/signals.hpp"
#include "load_frame_sim.hpp"
#include "pacer.hpp"
#include "shakedown_specimen.hpp"
#include "shaker_sim.hpp"
#include "world_clock.hpp"

using namespace hystlab;
using namespace hystlab::sim;

namespace {
std::unique_ptr<models::HysteresisModel> sma() { return std::make_unique<models::SimplifiedSmaModel>(models::table1_parameters()); }
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
  CHECK(f.state().displacement_mm < f.state().command_mm);                   // first-order lag
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

TEST_CASE("load frame: the e-stop latches; only a reset with the e-stop released clears it, and the drive needs enable again") {
  LoadFrameSim f(sma(), quiet());
  LoadFrameCommands c{2.0, 5.0, true, false, false};
  f.set_commands(c);
  run(f, 0.2);
  c.estop = true;
  f.set_commands(c);
  const double at = f.state().displacement_mm;
  run(f, 0.5);
  CHECK(f.state().displacement_mm == doctest::Approx(at).epsilon(0.01));
  CHECK(f.state().fault_code == kEstopPressed);
  c.estop = false;  // releasing the e-stop signal is not a reset
  f.set_commands(c);
  run(f, 0.5);
  CHECK(f.state().fault_code == kEstopPressed);
  CHECK((f.state().status_word & protocols::status::estop) != 0);
  CHECK((f.state().status_word & protocols::status::ready) == 0);
  CHECK(f.state().displacement_mm == doctest::Approx(at).epsilon(0.01));
  c.estop = true;  // a reset while the e-stop is on does nothing
  c.fault_reset = true;
  f.set_commands(c);
  c.estop = false;
  f.set_commands(c);  // fault_reset still 1: no new edge
  CHECK(f.state().fault_code == kEstopPressed);
  c.fault_reset = false;
  f.set_commands(c);
  c.fault_reset = true;  // the rising edge with the e-stop released
  f.set_commands(c);
  CHECK(f.state().fault_code == kNoFault);
  CHECK(f.state().status_word == protocols::status::ready);  // enable was dropped by the reset
  run(f, 0.5);
  CHECK(f.state().displacement_mm == doctest::Approx(at).epsilon(0.01));  // enable still 1 from before: no edge
  c.enable = false;
  f.set_commands(c);
  c.enable = true;
  f.set_commands(c);
  run(f, 0.5);
  CHECK(f.state().displacement_mm > at + 0.5);
  CHECK((f.state().status_word & protocols::status::enabled) != 0);
}

TEST_CASE("load frame: a latched fault holds, shows in the status word, and needs the reset") {
  LoadFrameSim f(sma(), quiet());
  LoadFrameCommands c{3.0, 5.0, true, false, false};
  f.set_commands(c);
  run(f, 0.2);
  f.latch_fault(7);
  const double at = f.state().displacement_mm;
  run(f, 0.3);
  CHECK(f.state().fault_code == 7);
  CHECK((f.state().status_word & protocols::status::fault) != 0);
  CHECK((f.state().status_word & (protocols::status::ready | protocols::status::enabled | protocols::status::limit_tripped)) == 0);
  CHECK(f.state().displacement_mm == doctest::Approx(at).epsilon(1e-3));
  f.latch_fault(9);  // the first fault stays the one reported
  CHECK(f.state().fault_code == 7);
  c.fault_reset = true;
  f.set_commands(c);
  CHECK(f.state().fault_code == kNoFault);
  CHECK((f.state().status_word & protocols::status::ready) != 0);
}

TEST_CASE("load frame: a limit trip stays latched after a reset while the frame is beyond the limit, on a controller without limit recovery") {
  LoadFrameParams p = quiet();
  p.limit_mm = 2.0;
  p.controller.limit_recovery = false;
  LoadFrameSim f(sma(), p);
  LoadFrameCommands c{5.0, 50.0, true, false, false};
  f.set_commands(c);
  run(f, 1.0);
  REQUIRE(f.state().fault_code == kDisplacementLimit);
  REQUIRE(std::fabs(f.state().displacement_mm) > 2.0);
  c.fault_reset = true;
  f.set_commands(c);
  run(f, 0.1);
  CHECK(f.state().fault_code == kDisplacementLimit);
  CHECK((f.state().status_word & protocols::status::limit_tripped) != 0);
  CHECK(f.state().displacement_mm < 2.1);
}

// A frame that left its stroke fast (at the valve's speed the actuator runs up to 0.45 mm past
// the limit in its last sample) is reset into limit recovery and may only come back, slowly.
TEST_CASE("load frame: limit recovery: after a reset beyond the stroke the frame moves only back, at most at the recovery rate") {
  namespace st = protocols::status;
  LoadFrameParams p = quiet();
  p.limit_mm = 2.0;
  LoadFrameSim f(sma(), p);
  LoadFrameCommands c{5.0, 500.0, true, false, false};
  f.set_commands(c);
  run(f, 0.5);
  REQUIRE(f.state().fault_code == kDisplacementLimit);
  const double tripped_at = f.state().displacement_mm;
  CAPTURE(tripped_at);
  REQUIRE(tripped_at > 2.05);
  c.fault_reset = true;  // the reset, enable still written high
  f.set_commands(c);
  run(f, 0.2);
  CHECK(f.state().fault_code == kNoFault);
  CHECK((f.state().status_word & (st::ready | st::limit_tripped)) == (st::ready | st::limit_tripped));
  CHECK((f.state().status_word & (st::fault | st::enabled)) == 0);  // enable needs a fresh rising edge
  CHECK(f.state().displacement_mm == doctest::Approx(tripped_at));
  c = {5.0, 500.0, false, false, false};
  f.set_commands(c);
  c.enable = true;  // outward, fast: taken as the limit, at the recovery rate
  f.set_commands(c);
  CHECK((f.state().status_word & st::enabled) != 0);
  run(f, 0.02);
  const double moved = tripped_at - f.state().displacement_mm;
  CHECK(moved > 0.0);
  CHECK(moved <= 0.02 * p.recovery_rate_mm_s + 1e-9);
  f.overtravel(4.0);  // pushed out again from outside: trips once more
  run(f, 0.1);
  CHECK(f.state().fault_code == kDisplacementLimit);
  CHECK((f.state().status_word & st::fault) != 0);
  CHECK(f.state().displacement_mm < tripped_at + 0.2);
  c.fault_reset = false, c.enable = false;
  f.set_commands(c);
  c.fault_reset = true;
  f.set_commands(c);
  c.fault_reset = false, c.enable = true, c.setpoint_mm = 0.0;  // back in: slowly while beyond, then as asked
  f.set_commands(c);
  const double x0 = f.state().displacement_mm;
  run(f, 0.05);
  CHECK(x0 - f.state().displacement_mm <= 0.05 * p.recovery_rate_mm_s + 1e-9);
  run(f, 1.0);
  CHECK((f.state().status_word & (st::limit_tripped | st::fault)) == 0);
  CHECK(f.state().displacement_mm == doctest::Approx(0.0).epsilon(1e-3));
}

TEST_CASE("load frame: an overtravel pushes the idle frame out of its stroke and trips it there") {
  LoadFrameParams p = quiet();
  LoadFrameSim f(sma(), p);
  f.overtravel(13.0);
  run(f, 2.0);
  CHECK(std::fabs(f.state().displacement_mm - 10.0) < 0.03);  // 5 mm/s for 2 s, nobody driving (0.025 mm of lag)
  run(f, 1.0);
  CHECK(f.state().fault_code == kDisplacementLimit);
  CHECK(f.state().displacement_mm > 12.0);
  CHECK(f.state().displacement_mm < 12.05);
}

TEST_CASE("load frame: the servo dead band leaves the frame short of the target, and not moving") {
  LoadFrameParams p = quiet();
  p.deadband_mm = 0.02;
  LoadFrameSim f(sma(), p);
  f.set_commands({4.0, 20.0, true, false, false});
  run(f, 1.0);
  CHECK(f.state().command_mm == doctest::Approx(4.0));
  // It stops within one step's correction (18 % of the error at 1 ms, τ = 5 ms) of the band's edge.
  CHECK(4.0 - f.state().displacement_mm < 0.02);
  CHECK(4.0 - f.state().displacement_mm > 0.016);
  CHECK((f.state().status_word & protocols::status::moving) == 0);
  LoadFrameSim g(sma(), quiet());  // without a dead band it gets there
  g.set_commands({4.0, 20.0, true, false, false});
  run(g, 1.0);
  CHECK(g.state().displacement_mm == doctest::Approx(4.0).epsilon(1e-4));
}

TEST_CASE("load frame: the mode interlock: enable is taken, but nothing moves outside the configured mode") {
  LoadFrameParams p = quiet();
  p.controller.mode_interlock = true;
  p.controller.mode = 1;
  LoadFrameSim f(sma(), p);
  LoadFrameCommands c{2.0, 10.0, true, false, false};
  f.set_commands(c);  // mode 0, as the register starts
  run(f, 0.5);
  CHECK(f.state().displacement_mm == 0.0);
  CHECK((f.state().status_word & protocols::status::enabled) == 0);
  CHECK((f.state().status_word & protocols::status::ready) != 0);  // the mode does not affect ready
  c.mode = 1;
  f.set_commands(c);
  run(f, 0.5);
  CHECK(f.state().displacement_mm > 1.9);
  CHECK((f.state().status_word & protocols::status::enabled) != 0);
}

TEST_CASE("load frame: the host heartbeat watchdog latches fault 4 once the host stops") {
  LoadFrameParams p = quiet();
  p.controller.host_timeout_s = 0.1;
  LoadFrameSim f(sma(), p);
  LoadFrameCommands c{10.0, 2.0, true, false, false};
  f.set_commands(c);
  run(f, 0.5);  // never written: the watchdog is not armed
  CHECK(f.state().fault_code == kNoFault);
  for (std::uint32_t k = 1; k <= 20; ++k) {  // a host alive every 50 ms
    c.host_heartbeat = k;
    f.set_commands(c);
    run(f, 0.05);
  }
  CHECK(f.state().fault_code == kNoFault);
  const double at = f.state().displacement_mm;
  run(f, 0.2);  // the host is gone
  CHECK(f.state().fault_code == kHostHeartbeatLost);
  CHECK((f.state().status_word & protocols::status::fault) != 0);
  CHECK(f.state().displacement_mm < at + 0.25);  // stopped at about at + 0.1 s × 2 mm/s
}

TEST_CASE("the simulator's fault codes have their texts in the shipped maps") {
  const auto frame = protocols::RegisterMap::from_json(protocols::kDefaultLoadFrameMap);
  for (std::uint16_t code : {kDisplacementLimit, kForceLimit, kEstopPressed, kHostHeartbeatLost, kOperatorLatch}) {
    CAPTURE(code);
    CHECK_FALSE(frame.fault_text(code).empty());
  }
  CHECK(frame.fault_text(kHostHeartbeatLost) == "host heartbeat lost");
  const auto shaker = protocols::RegisterMap::from_json(protocols::kDefaultShakerMap);
  for (std::uint16_t code : {kEstopPressed, kHostHeartbeatLost, kOperatorLatch}) CHECK_FALSE(shaker.fault_text(code).empty());
}

namespace {
// The work ∮ f dδ of a specimen over one loop 0 -> top -> 0 in 1600 steps (trapezoids).
template <class Specimen>
double loop_work(Specimen& s, double top) {
  double work = 0, xp = 0, fp = s.step(0.0);
  for (int k = 1; k <= 1600; ++k) {
    const double x = k <= 800 ? top * k / 800 : top * (1600 - k) / 800;
    const double f = s.step(x);
    work += 0.5 * (f + fp) * (x - xp);
    xp = x, fp = f;
  }
  return work;
}
}  // namespace

TEST_CASE("specimen smoothing: corners rounded, straight parts exact, nearly independent of the step size") {
  const double w = 0.05;
  SmoothedSpecimen coarse(sma(), w), fine(sma(), w);
  models::SimplifiedSmaModel sharp(models::table1_parameters());
  double worst = 0, at_mf = 0, on_line = 0;
  for (int k = 1; k <= 4000; ++k) {
    const double x = 4.0 * k / 4000.0;
    const double s = coarse.step(x);
    for (int j = 1; j <= 10; ++j) fine.step(4.0 * (k - 1 + j / 10.0) / 4000.0);
    const double f = sharp.step(x);
    worst = std::max(worst, std::fabs(s - f));
    if (x > 3.4 && x < 3.7) at_mf = std::max(at_mf, f - s);
    if (x > 0.1 && x < 0.9) on_line = std::max(on_line, std::fabs(s - f));  // the austenite line, no corner behind
    CHECK(std::fabs(fine.step(x) - s) < 0.16);                              // 0.1 % of full scale: the update is first order in the step
  }
  CHECK(at_mf > 2.0);            // the corner at Mf (12 -> 150 N/mm) is rounded off
  CHECK(on_line < 1e-9);         // no lag on a straight part
  CHECK(worst < 150 * w * 1.2);  // never more than the stiffest slope times the width
  // An elastic loop on the austenite line dissipates nothing: the smoothing adds no loop of its own
  // (the force filter before stop 23 gave -3 N·mm here, a spring returning more than it took).
  SmoothedSpecimen elastic(sma(), w);
  CHECK(std::fabs(loop_work(elastic, 0.8)) < 1e-6);
}

TEST_CASE("shaker: rests at its preload, follows the base at low frequency, refuses an unstable step") {
  const models::SimplifiedSmaModel spring(models::table1_parameters());
  ShakerSim s(spring, ShakerParams{});
  CHECK(s.preload_mm() > 0);
  s.step(0.5);
  CHECK(std::fabs(s.state().mass_displacement_mm) < 1e-3);  // static equilibrium
  s.set_drive(2.0, 0.2, true);                              // far below resonance (17.7 Hz): transmissibility ≈ 1
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

// The drive's sine at steady state: the base amplitude per unit of drive (least squares at f).
double table_response(ShakerParams p, double f, double drive_mm) {
  const models::SimplifiedSmaModel spring(models::table1_parameters());
  ShakerSim s(spring, p);
  s.set_drive(f, drive_mm, true);
  s.step(std::max(1.0, 40 / f));  // past the transient
  std::vector<double> t, y;
  for (int k = 0; k < 4000; ++k) {
    s.step(1e-4 * std::max(1.0, 20 / f));
    t.push_back(s.state().time_s), y.push_back(s.state().base_displacement_mm);
  }
  return models::fit_sine(t, y, f).amplitude / drive_mm;
}

TEST_CASE("shaker: the table is a servo that the isolator loads: its response depends on the frequency and on the load") {
  ShakerParams p;
  // Unloaded in effect (a light mass far from its resonance): a second-order servo, |H| = 1/sqrt((1-r²)² + (2ζr)²).
  const double r = 30.0 / p.servo_hz, servo = 1 / std::sqrt((1 - r * r) * (1 - r * r) + 4 * p.servo_damping * p.servo_damping * r * r);
  ShakerParams light = p;
  light.mass_kg = 0.2;  // resonance far above 30 Hz, a load of 1 % of the table's
  CHECK(table_response(light, 30.0, 0.01) == doctest::Approx(servo).epsilon(0.03));
  CHECK(table_response(light, 2.0, 0.01) == doctest::Approx(1.0).epsilon(0.01));
  CHECK(table_response(light, 120.0, 0.01) < 0.5);  // beyond the servo's bandwidth
  // At the default isolator's resonance (17.7 Hz) the mass pulls on the table: the response dips
  // well below what the same table gives with a light mass.
  const double loaded = table_response(p, 17.7, 0.005), unloaded = table_response(light, 17.7, 0.005);
  CAPTURE(loaded);
  CAPTURE(unloaded);
  CHECK(loaded < 0.8 * unloaded);
  // servo_hz = 0: an ideal table that follows the drive.
  ShakerParams ideal = p;
  ideal.servo_hz = 0;
  CHECK(table_response(ideal, 17.7, 0.005) == doctest::Approx(1.0).epsilon(1e-3));
}

TEST_CASE("shaker: an e-stop or a latched fault stops the drive at zero amplitude; enable is ignored until a reset and a new enable") {
  const models::SimplifiedSmaModel spring(models::table1_parameters());
  ShakerSim s(spring, ShakerParams{});
  ShakerCommands c{5.0, 0.3, true};
  s.set_commands(c);
  s.step(0.3);
  CHECK((s.state().status_word & protocols::status::enabled) != 0);
  CHECK((s.state().status_word & protocols::status::moving) != 0);
  s.press_estop();
  s.set_drive(5.0, 0.3, true);  // enable again: ignored while latched
  double base_max = 0;
  for (int k = 0; k < 300; ++k) {  // the table coasts to rest (its servo now holds zero)
    s.step(1e-3);
    if (k >= 200) base_max = std::max(base_max, std::fabs(s.state().base_displacement_mm));
  }
  CHECK(base_max < 0.01);
  CHECK(s.state().fault_code == kEstopPressed);
  CHECK((s.state().status_word & (protocols::status::estop | protocols::status::fault)) == (protocols::status::estop | protocols::status::fault));
  c.fault_reset = true;
  s.set_commands(c);
  CHECK(s.state().fault_code == kNoFault);
  c.enable = false;
  c.fault_reset = false;
  s.set_commands(c);
  c.enable = true;
  s.set_commands(c);
  base_max = 0;
  for (int k = 0; k < 600; ++k) {
    s.step(1e-3);
    if (k >= 300) base_max = std::max(base_max, std::fabs(s.state().base_displacement_mm));
  }
  CHECK(base_max == doctest::Approx(0.3).epsilon(0.05));  // 5 Hz: the table follows its drive
  s.latch_fault(5);
  s.step(0.3);
  CHECK(std::fabs(s.state().base_displacement_mm) < 0.01);
  CHECK(s.state().fault_code == kOperatorLatch);
}

TEST_CASE("load frame: the watchdog arms at the host's first heartbeat and times from then") {
  LoadFrameParams p = quiet();
  p.controller.host_timeout_s = 0.2;
  p.controller.mode_interlock = true;
  LoadFrameSim f(sma(), p);
  LoadFrameCommands c{10.0, 2.0, false, false, false};
  c.mode = 1;
  f.set_commands(c);
  run(f, 0.3);
  c.enable = true;
  f.set_commands(c);
  run(f, 0.3);
  c.host_heartbeat = 3;
  f.set_commands(c);
  run(f, 0.1);
  CHECK(f.state().fault_code == kNoFault);
  run(f, 0.15);
  CHECK(f.state().fault_code == kHostHeartbeatLost);
}

TEST_CASE("pacer: a time-scaled world waits for its host, and one late request does not widen its lead") {
  sim::Pacer off(false);
  CHECK(off.horizon(5.0) == 5.0);
  CHECK(off.on_request(5.0, 1.0) == 1.0);

  sim::Pacer p(true);
  CHECK(p.horizon(0.5) == 0.5);  // no host yet: the world runs freely
  double world = 0;
  for (int k = 0; k <= 10; ++k) {  // a host asking every millisecond
    const double now = 0.001 * k;
    world = p.on_request(now, world);
    world = std::max(world, p.horizon(now));
  }
  CHECK(world == doctest::Approx(0.010));
  CHECK(p.window_s() == doctest::Approx(0.003));
  CHECK(p.lost_s() == 0);
  // The host stalls for 0.6 s: the world stops 3 ms past its last request, and goes on from 3 ms
  // before the next one; the rest is counted as lost.
  CHECK(p.horizon(0.3) == doctest::Approx(0.013));
  world = p.on_request(0.61, 0.013);
  CHECK(world == doctest::Approx(0.607));
  CHECK(p.lost_s() == doctest::Approx(0.594));
  CHECK(p.window_s() == doctest::Approx(0.003));  // the median of 8: one late request is not the rhythm
  // A slower host (idle polling every 50 ms) gets a wider lead, up to 200 ms.
  for (int k = 1; k <= 8; ++k) world = std::max(p.on_request(0.61 + 0.05 * k, world), p.horizon(0.61 + 0.05 * k));
  CHECK(p.window_s() == doctest::Approx(0.15));
  for (int k = 1; k <= 8; ++k) (void)p.on_request(1.01 + 0.1 * k, 2.0);
  CHECK(p.window_s() == doctest::Approx(sim::Pacer::kMaxWindow_s));
}

TEST_CASE("world clock: steps follow the wall clock; after a freeze at most 20 ms is caught up, the rest counted lost") {
  sim::WorldClock w(10.0, 0.001, false);  // time scale 10, 1 kHz: 10 steps a wall millisecond
  long steps = 0;
  for (int k = 1; k <= 15; ++k) steps += w.steps_due(0.001 * k);
  CHECK(steps == 150);
  CHECK(w.lost_s() == 0);
  steps = w.steps_due(0.515);  // the machine froze for half a second
  CHECK(steps == 200);         // 20 ms of it, at time scale 10
  CHECK(w.lost_s() == doctest::Approx(0.48));
  CHECK(w.steps_due(0.516) == 10);  // and on as before
}

TEST_CASE("shakedown specimen: the upper plateau comes down cycle by cycle and settles, the force continuous") {
  const models::SmaParameters settled = models::table1_parameters();
  ShakedownSpecimen s(settled, 10.0, 3.0);
  models::SimplifiedSmaModel trained(settled);
  std::vector<double> energy;
  double x = 0, f = s.step(0.0), work = 0, jump = 0;
  for (int c = 0; c < 15; ++c)
    for (int k = 1; k <= 1600; ++k) {
      const double xn = k <= 800 ? 4.0 * k / 800 : 4.0 * (1600 - k) / 800;
      const double fn = s.step(xn);
      jump = std::max(jump, std::fabs(fn - f) - 150 * std::fabs(xn - x) - 1e-9);  // never more than the stiffest slope
      work += 0.5 * (f + fn) * (xn - x);
      x = xn, f = fn;
      if (k == 1600) energy.push_back(work), work = 0;
    }
  CHECK(s.cycles() == 15);
  CHECK(jump <= 0);
  // The settled loop's energy, from the trained model.
  const double e_settled = loop_work(trained, 4.0);
  for (std::size_t c = 1; c < energy.size(); ++c) {
    CAPTURE(c);
    CHECK(energy[c] < energy[c - 1]);  // the loop narrows every cycle
  }
  CHECK(energy.front() > 1.2 * e_settled);
  CHECK(energy.back() == doctest::Approx(e_settled).epsilon(0.01));
  // The forward plateau at cycle n is 10 e^{-n/3} N above the settled one.
  CHECK(models::transitions(s.parameters_of(3)).Ms.force - models::transitions(settled).Ms.force == doctest::Approx(10 * std::exp(-1.0)));
  CHECK(models::transitions(s.parameters_of(3)).As.force == doctest::Approx(models::transitions(settled).As.force));
}
