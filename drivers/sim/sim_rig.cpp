#include "sim_rig.hpp"

#include <cmath>
#include <limits>
#include <sstream>

namespace hystlab::sim {
using protocols::Signal;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
double& at(SignalValues& v, Signal s) { return v[static_cast<std::size_t>(s)]; }
double at(const SignalValues& v, Signal s) { return v[static_cast<std::size_t>(s)]; }
}  // namespace

std::string Faults::apply(const std::string& spec) {
  const auto eq = spec.find('=');
  const std::string name = spec.substr(0, eq);
  int value = 0;
  if (eq != std::string::npos) {
    try {
      value = std::stoi(spec.substr(eq + 1));
    } catch (...) {
      return "fault '" + name + "': value '" + spec.substr(eq + 1) + "' is not a whole number";
    }
  }
  if (name == "drop") drop = true;
  else if (name == "delay") delay_ms = value > 0 ? value : 200;
  else if (name == "stall") stall_ms = value > 0 ? value : 30;
  else if (name == "exception") exception = value > 0 ? value : 4;
  else if (name == "crc") crc = true;
  else if (name == "freeze") freeze = true;
  else if (name == "overload") overload = true;
  else if (name == "can-silent") can_silent = true;
  else if (name == "clear") *this = Faults{};
  else return "unknown fault '" + name + "' (drop, delay=MS, stall=MS, exception=CODE, crc, freeze, overload, can-silent, clear)";
  return "";
}

std::string Faults::describe() const {
  std::ostringstream s;
  s << "drop=" << drop << " delay=" << delay_ms << " stall=" << stall_ms << " exception=" << exception << " crc=" << crc << " freeze=" << freeze
    << " overload=" << overload << " can-silent=" << can_silent;
  return s.str();
}

void SimRig::step(double dt) noexcept {
  if (frame_) frame_->step(dt);
  else shaker_->step(dt);
}

void SimRig::apply(const SignalValues& v) noexcept {
  auto given = [&](Signal s) { return !std::isnan(at(v, s)); };
  if (frame_) {
    if (given(Signal::setpoint_mm)) frame_cmd_.setpoint_mm = at(v, Signal::setpoint_mm);
    if (given(Signal::ramp_rate_mm_s)) frame_cmd_.ramp_rate_mm_s = at(v, Signal::ramp_rate_mm_s);
    if (given(Signal::enable)) frame_cmd_.enable = at(v, Signal::enable) != 0;
    if (given(Signal::hold)) frame_cmd_.hold = at(v, Signal::hold) != 0;
    if (given(Signal::estop)) {
      const bool was = frame_cmd_.estop;
      frame_cmd_.estop = at(v, Signal::estop) != 0;
      frame_->set_commands(frame_cmd_);
      if (was && !frame_cmd_.estop) frame_->reset_fault();  // releasing the e-stop resets the trip
    }
    frame_->set_commands(frame_cmd_);
    return;
  }
  if (given(Signal::drive_frequency_hz)) freq_ = at(v, Signal::drive_frequency_hz);
  if (given(Signal::drive_amplitude_mm)) amp_ = at(v, Signal::drive_amplitude_mm);
  if (given(Signal::shaker_enable)) shaker_on_ = at(v, Signal::shaker_enable) != 0;
  if (given(Signal::estop) && at(v, Signal::estop) != 0) shaker_on_ = false;
  shaker_->set_drive(freq_, amp_, shaker_on_);
}

SignalValues SimRig::measurements(const Faults& faults) const noexcept {
  SignalValues v;
  v.fill(kNaN);
  if (frame_) {
    const LoadFrameState& s = frame_->state();
    at(v, Signal::displacement_mm) = s.displacement_mm;
    at(v, Signal::force_N) = faults.overload ? 1e5 : s.force_N;
    at(v, Signal::command_mm) = s.command_mm;
    at(v, Signal::status_word) = s.status_word;
    at(v, Signal::fault_code) = s.fault_code;
    at(v, Signal::heartbeat) = s.heartbeat;
    at(v, Signal::sample_counter) = s.sample_counter;
  } else {
    const ShakerState& s = shaker_->state();
    at(v, Signal::base_accel_m_s2) = s.base_accel_m_s2;
    at(v, Signal::mass_accel_m_s2) = s.mass_accel_m_s2;
    at(v, Signal::base_displacement_mm) = s.base_displacement_mm;
    at(v, Signal::mass_displacement_mm) = s.mass_displacement_mm;
    at(v, Signal::status_word) = s.status_word;
    at(v, Signal::fault_code) = s.fault_code;
    at(v, Signal::heartbeat) = s.heartbeat;
    at(v, Signal::sample_counter) = s.sample_counter;
  }
  return v;
}

}  // namespace hystlab::sim
