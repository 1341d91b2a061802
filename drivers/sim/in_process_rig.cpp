#include "in_process_rig.hpp"

#include <cmath>
#include <limits>

namespace hystlab::sim {
using protocols::Signal;

namespace {
SignalValues none() {
  SignalValues v;
  v.fill(std::numeric_limits<double>::quiet_NaN());
  return v;
}
double at(const SignalValues& v, Signal s) { return v[static_cast<std::size_t>(s)]; }
std::uint16_t word(double v) { return std::isnan(v) ? std::uint16_t{0} : static_cast<std::uint16_t>(v); }
std::uint32_t count(double v) { return std::isnan(v) ? 0U : static_cast<std::uint32_t>(v); }
}  // namespace

InProcessRig::InProcessRig(SimRig rig, double sample_rate_hz) : rig_(std::move(rig)), period_s_(1.0 / sample_rate_hz) {}

std::error_code InProcessRig::connect(double now_s) noexcept {
  advance(now_s);
  return {};
}

// The controller's clock runs from the first time the host passes in, one sample per period; a
// period not yet whole waits for the next call (as hystlab-sim's world clock does). The host's
// time may start again (each campaign counts from its own start): the controller's runs on.
void InProcessRig::advance(double now_s) noexcept {
  if (!anchored_ || now_s < last_now_s_) {
    anchor_s_ = now_s - rig_.time_s();
    anchored_ = true;
  }
  last_now_s_ = now_s;
  // Counted in whole periods from the anchor, so rounding never drifts the controller's clock.
  const double due = std::floor((now_s - anchor_s_) / period_s_ + 1e-9);
  for (double done = std::round(rig_.time_s() / period_s_); done < due; done += 1) rig_.step(period_s_);
}

std::error_code InProcessRig::write(Signal s, double v) noexcept {
  SignalValues values = none();
  values[static_cast<std::size_t>(s)] = v;
  rig_.apply(values);
  return {};
}

std::error_code InProcessRig::arm(bool enable) noexcept { return write(Signal::enable, enable ? 1.0 : 0.0); }
std::error_code InProcessRig::hold(bool on) noexcept { return write(Signal::hold, on ? 1.0 : 0.0); }
std::error_code InProcessRig::estop(bool on) noexcept { return write(Signal::estop, on ? 1.0 : 0.0); }
std::error_code InProcessRig::set_mode(std::uint16_t mode) noexcept { return write(Signal::mode, mode); }
std::error_code InProcessRig::write_host_heartbeat(std::uint32_t value) noexcept { return write(Signal::host_heartbeat, value); }

std::error_code InProcessRig::command(double setpoint_mm, double ramp_rate_mm_s) noexcept {
  SignalValues v = none();
  v[static_cast<std::size_t>(Signal::setpoint_mm)] = setpoint_mm;
  v[static_cast<std::size_t>(Signal::ramp_rate_mm_s)] = ramp_rate_mm_s;
  rig_.apply(v);
  return {};
}

// As ModbusRig::reset_faults: the e-stop signal released, then fault_reset pulsed (a rising edge).
std::error_code InProcessRig::reset_faults() noexcept {
  (void)write(Signal::estop, 0);
  (void)write(Signal::fault_reset, 1);
  return write(Signal::fault_reset, 0);
}

std::error_code InProcessRig::command_shaker(double frequency_hz, double amplitude_mm, bool enable) noexcept {
  if (rig_.kind() != protocols::RigKind::shaker) return drivers::RigError::unsupported;
  SignalValues v = none();
  v[static_cast<std::size_t>(Signal::drive_frequency_hz)] = frequency_hz;
  v[static_cast<std::size_t>(Signal::drive_amplitude_mm)] = amplitude_mm;
  v[static_cast<std::size_t>(Signal::shaker_enable)] = enable ? 1.0 : 0.0;
  rig_.apply(v);
  return {};
}

std::error_code InProcessRig::read_sample(double now_s, drivers::RigSample& out) noexcept {
  if (rig_.kind() != protocols::RigKind::load_frame) return drivers::RigError::unsupported;
  advance(now_s);
  const SignalValues m = rig_.measurements(faults_);
  out.time_s = now_s;
  out.command_mm = at(m, Signal::command_mm);
  out.displacement_mm = at(m, Signal::displacement_mm);
  out.force_N = at(m, Signal::force_N);
  out.status_word = word(at(m, Signal::status_word));
  out.fault_code = word(at(m, Signal::fault_code));
  out.heartbeat = count(at(m, Signal::heartbeat));
  out.sample_counter = count(at(m, Signal::sample_counter));
  return {};
}

std::error_code InProcessRig::read_shaker(double now_s, drivers::ShakerSample& out) noexcept {
  if (rig_.kind() != protocols::RigKind::shaker) return drivers::RigError::unsupported;
  advance(now_s);
  const SignalValues m = rig_.measurements(faults_);
  out.time_s = now_s;
  out.base_accel_m_s2 = at(m, Signal::base_accel_m_s2);
  out.mass_accel_m_s2 = at(m, Signal::mass_accel_m_s2);
  out.base_displacement_mm = at(m, Signal::base_displacement_mm);
  out.mass_displacement_mm = at(m, Signal::mass_displacement_mm);
  out.status_word = word(at(m, Signal::status_word));
  out.fault_code = word(at(m, Signal::fault_code));
  out.heartbeat = count(at(m, Signal::heartbeat));
  out.sample_counter = count(at(m, Signal::sample_counter));
  return {};
}

}  // namespace hystlab::sim
