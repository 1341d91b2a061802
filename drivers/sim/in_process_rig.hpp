#pragma once
// hystlab-sim's physics and controller as a drivers::Rig in the caller's process, on the caller's
// clock (ros2_control's fake hardware): the same SimRig the simulator serves over Modbus and CAN,
// stepped at its sample rate up to the time each read passes in. On a fake clock a campaign's
// outcome is then a function of its inputs alone: the tests of control quality through the
// isolator's resonance run here, not against a simulator that a loaded machine starves (issue 40:
// a real-time run read the base's weakest window 0.896 of its demand where five others read 0.91-0.94).
// Signals map as the Modbus map's do (drivers/src/modbus_rig.cpp): arm writes enable, reset pulses
// fault_reset after releasing the e-stop signal, a shaker's drive writes frequency, amplitude and
// enable. No link faults: those are the Modbus and CAN tests' business.
#include <cstdint>
#include <string>
#include <system_error>

#include "faults.hpp"
#include "hystlab/drivers/rig.hpp"
#include "sim_rig.hpp"

namespace hystlab::sim {

class InProcessRig final : public drivers::Rig {
 public:
  // sample_rate_hz: the controller's own sample clock (each step takes one sample).
  InProcessRig(SimRig rig, double sample_rate_hz);

  std::error_code connect(double now_s) noexcept override;
  void disconnect() noexcept override {}
  std::error_code arm(bool enable) noexcept override;
  std::error_code command(double setpoint_mm, double ramp_rate_mm_s) noexcept override;
  std::error_code hold(bool on) noexcept override;
  std::error_code estop(bool on) noexcept override;
  std::error_code read_sample(double now_s, drivers::RigSample& out) noexcept override;
  std::error_code set_mode(std::uint16_t mode) noexcept override;
  std::error_code reset_faults() noexcept override;
  std::error_code write_host_heartbeat(std::uint32_t value) noexcept override;
  std::error_code command_shaker(double frequency_hz, double amplitude_mm, bool enable) noexcept override;
  std::error_code read_shaker(double now_s, drivers::ShakerSample& out) noexcept override;
  [[nodiscard]] drivers::IoHealthSnapshot health() const noexcept override { return {}; }
  [[nodiscard]] std::string describe() const override { return "in-process simulated rig"; }

  // The physics, for a test's assertions and for the operator's controller events.
  [[nodiscard]] SimRig& sim() noexcept { return rig_; }
  [[nodiscard]] double sim_time_s() const noexcept { return rig_.time_s(); }

 private:
  void advance(double now_s) noexcept;  // steps the physics up to now_s (the first call anchors it)
  std::error_code write(protocols::Signal s, double v) noexcept;
  SimRig rig_;
  Faults faults_;  // none: measurements as the controller has them
  double period_s_;
  double anchor_s_ = 0, last_now_s_ = 0;
  bool anchored_ = false;
};

}  // namespace hystlab::sim
