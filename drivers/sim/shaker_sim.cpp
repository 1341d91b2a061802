#include "shaker_sim.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "hystlab/protocols/signals.hpp"

namespace hystlab::sim {
namespace {
constexpr double kG = 9.81;
}

ShakerSim::ShakerSim(const models::HysteresisModel& spring, ShakerParams params) : p_(params), ctl_(params.controller) {
  if (!(p_.mass_kg > 0) || p_.springs < 1 || !(p_.dt_s > 0)) throw std::invalid_argument("shaker: mass, springs and dt must be > 0");
  const double omega = std::sqrt(p_.springs * p_.k_max_N_per_mm * 1e3 / p_.mass_kg);
  if (omega * p_.dt_s > 0.5) throw std::invalid_argument("shaker: time step too large for the spring stiffness (dt·ω > 0.5)");
  if (p_.servo_hz < 0 || (p_.servo_hz > 0 && !(p_.table_mass_kg > 0)) || p_.servo_damping < 0)
    throw std::invalid_argument("shaker: servo_hz ≥ 0, servo_damping ≥ 0 and table_mass_kg > 0");
  if (2 * std::numbers::pi * p_.servo_hz * p_.dt_s > 0.5) throw std::invalid_argument("shaker: time step too large for the servo (dt·ω > 0.5)");
  // Static preload: the compression at which N springs carry the weight (bisection on copies
  // loaded as the weight loads them, in small steps), and the weight is then what they carry:
  // stepped from 0 to the preload at once, the springs' force at rest did not balance the
  // weight, and the mass rested 0.13 mm low (seen on the page's shared displacement axis).
  const auto loaded = [&](double x) {
    auto s = spring.clone();
    s->reset();
    constexpr int kSteps = 400;
    for (int i = 1; i <= kSteps; ++i) s->step(x * i / kSteps);
    for (int i = 0; i < 20; ++i) s->step(x);  // at rest there
    return s;
  };
  double lo = 0, hi = 10;
  for (int k = 0; k < 50; ++k) {
    const double mid = 0.5 * (lo + hi);
    (p_.springs * loaded(mid)->step(mid) < p_.mass_kg * kG ? lo : hi) = mid;
  }
  preload_mm_ = 0.5 * (lo + hi);
  weight_N_ = 0;
  for (int k = 0; k < p_.springs; ++k) {
    springs_.push_back(loaded(preload_mm_));
    weight_N_ += springs_.back()->step(preload_mm_);  // what they carry at rest: the mass rests at 0
  }
  publish_status();
}

void ShakerSim::set_commands(const ShakerCommands& c) noexcept {
  cmd_ = c;
  ctl_.command(HostCommands{c.enable, c.estop, c.fault_reset, c.mode, c.host_heartbeat}, state_.time_s, false);
  publish_status();
}

void ShakerSim::set_drive(double frequency_hz, double amplitude_mm, bool enable) noexcept {
  ShakerCommands c = cmd_;
  c.frequency_hz = frequency_hz;
  c.amplitude_mm = amplitude_mm;
  c.enable = enable;
  set_commands(c);
}

void ShakerSim::press_estop() noexcept {
  ctl_.press_estop();
  publish_status();
}

void ShakerSim::latch_fault(std::uint16_t code) noexcept {
  ctl_.latch(code);
  publish_status();
}

void ShakerSim::publish_status() noexcept {
  const bool shaking = ctl_.drive_on() && cmd_.amplitude_mm > 0 && cmd_.frequency_hz > 0;
  state_.fault_code = ctl_.fault_code();
  state_.status_word = static_cast<std::uint16_t>(ctl_.status_bits() | (shaking ? protocols::status::moving : 0U));
}

void ShakerSim::integrate_once() noexcept {
  const double dt = p_.dt_s;
  const double w = 2 * std::numbers::pi * cmd_.frequency_hz;
  // Off, faulted or e-stopped: the drive goes to zero amplitude (the table comes to rest).
  const bool on = ctl_.drive_on();
  const double amplitude_m = cmd_.amplitude_mm * 1e-3;
  if (on) phase_ += w * dt;
  const double u = on ? amplitude_m * std::sin(phase_) : 0.0;
  const double compression_mm = preload_mm_ - (x_ - y_) * 1e3;
  double force = 0;
  for (auto& s : springs_) force += s->step(compression_mm);
  const double push = force - p_.damping_N_s_per_m * (v_ - yv_);  // springs and damper, up on the mass, down on the table
  const double a = (push - weight_N_) / p_.mass_kg;
  double ay = 0;
  if (p_.servo_hz > 0) {  // the servo pulls the table to the drive; the isolator's dynamic load pushes it back
    const double ws = 2 * std::numbers::pi * p_.servo_hz;
    ay = ws * ws * (u - y_) - 2 * p_.servo_damping * ws * yv_ - (push - weight_N_) / p_.table_mass_kg;
    yv_ += ay * dt;
    y_ += yv_ * dt;
  } else {  // an ideal table
    const double yv = on ? amplitude_m * w * std::cos(phase_) : 0.0;
    ay = on ? -amplitude_m * w * w * std::sin(phase_) : 0.0;
    y_ = u, yv_ = yv;
  }
  v_ += a * dt;  // semi-implicit Euler: velocity first, then position with the new velocity
  x_ += v_ * dt;
  state_.base_accel_m_s2 = ay;
  state_.mass_accel_m_s2 = a;
  state_.base_displacement_mm = y_ * 1e3;
  state_.mass_displacement_mm = x_ * 1e3;
}

void ShakerSim::step(double dt) noexcept {
  carry_ += dt;
  while (carry_ >= p_.dt_s) {
    integrate_once();
    carry_ -= p_.dt_s;
  }
  state_.time_s += dt;
  ctl_.watch(state_.time_s);
  publish_status();
  ++state_.heartbeat;
  ++state_.sample_counter;
}

}  // namespace hystlab::sim
