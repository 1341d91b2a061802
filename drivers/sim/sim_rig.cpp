#include "sim_rig.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace hystlab::sim {
using protocols::Signal;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
double& at(SignalValues& v, Signal s) { return v[static_cast<std::size_t>(s)]; }
double at(const SignalValues& v, Signal s) { return v[static_cast<std::size_t>(s)]; }

// The controller's commands common to both rigs; a value not given keeps the last one.
template <class Commands>
void apply_controller_commands(const SignalValues& v, Commands& c) {
  auto given = [&](Signal s) { return !std::isnan(at(v, s)); };
  if (given(Signal::estop)) c.estop = at(v, Signal::estop) != 0;
  if (given(Signal::fault_reset)) c.fault_reset = at(v, Signal::fault_reset) != 0;
  if (given(Signal::mode)) c.mode = static_cast<std::uint16_t>(std::clamp(at(v, Signal::mode), 0.0, 65535.0));
  if (given(Signal::host_heartbeat)) c.host_heartbeat = static_cast<std::uint32_t>(std::clamp(at(v, Signal::host_heartbeat), 0.0, 4294967295.0));
}
}  // namespace

void SimRig::step(double dt) noexcept {
  if (frame_)
    frame_->step(dt);
  else
    shaker_->step(dt);
}

void SimRig::apply(const SignalValues& v) noexcept {
  auto given = [&](Signal s) { return !std::isnan(at(v, s)); };
  if (frame_) {
    if (given(Signal::setpoint_mm)) frame_cmd_.setpoint_mm = at(v, Signal::setpoint_mm);
    if (given(Signal::ramp_rate_mm_s)) frame_cmd_.ramp_rate_mm_s = at(v, Signal::ramp_rate_mm_s);
    if (given(Signal::enable)) frame_cmd_.enable = at(v, Signal::enable) != 0;
    if (given(Signal::hold)) frame_cmd_.hold = at(v, Signal::hold) != 0;
    apply_controller_commands(v, frame_cmd_);
    frame_->set_commands(frame_cmd_);
    return;
  }
  if (given(Signal::drive_frequency_hz)) shaker_cmd_.frequency_hz = at(v, Signal::drive_frequency_hz);
  if (given(Signal::drive_amplitude_mm)) shaker_cmd_.amplitude_mm = at(v, Signal::drive_amplitude_mm);
  if (given(Signal::shaker_enable)) shaker_cmd_.enable = at(v, Signal::shaker_enable) != 0;
  apply_controller_commands(v, shaker_cmd_);
  shaker_->set_commands(shaker_cmd_);
}

void SimRig::press_estop() noexcept {
  if (frame_)
    frame_->press_estop();
  else
    shaker_->press_estop();
}

void SimRig::latch_fault(std::uint16_t code) noexcept {
  if (frame_)
    frame_->latch_fault(code);
  else
    shaker_->latch_fault(code);
}

std::string SimRig::set_deadband(double mm) {
  if (!frame_) return "fault 'deadband': a shaker has no position servo";
  frame_->set_deadband(mm);
  return "";
}

std::string SimRig::overtravel(double mm) {
  if (!frame_) return "fault 'overtravel': a shaker has no stroke to leave";
  frame_->overtravel(mm);
  return "";
}

bool SimRig::enable_command() const noexcept { return controller().enable_command(); }

std::string SimRig::describe_controller() const {
  std::ostringstream s;
  const Controller& c = controller();
  s << "fault_code=" << c.fault_code() << " stopped=" << c.stopped() << " enable=" << c.enable_command() << " mode_ok=" << c.mode_ok();
  if (frame_) s << " deadband=" << frame_->deadband() << " recovering=" << c.recovering();
  return s.str();
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
