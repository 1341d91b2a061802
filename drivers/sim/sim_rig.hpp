#pragma once
// The simulated rig as the servers see it: signal values in, signal values out, whatever the
// physics behind (load frame or shaker), and the operator's controller events.
#include <array>
#include <memory>
#include <optional>
#include <string>

#include "faults.hpp"
#include "hystlab/protocols/signals.hpp"
#include "load_frame_sim.hpp"
#include "shaker_sim.hpp"

namespace hystlab::sim {

using SignalValues = std::array<double, protocols::kSignalCount>;

class SimRig {
 public:
  explicit SimRig(std::unique_ptr<LoadFrameSim> frame) : frame_(std::move(frame)) {}
  explicit SimRig(std::unique_ptr<ShakerSim> shaker) : shaker_(std::move(shaker)) {}
  [[nodiscard]] protocols::RigKind kind() const noexcept { return frame_ ? protocols::RigKind::load_frame : protocols::RigKind::shaker; }
  void step(double dt) noexcept;
  // Command signals present in values (NaN: not given) are applied.
  void apply(const SignalValues& values) noexcept;
  // Measurements (NaN for signals this rig has not), with the overload fault applied.
  [[nodiscard]] SignalValues measurements(const Faults& faults) const noexcept;
  [[nodiscard]] double time_s() const noexcept { return frame_ ? frame_->state().time_s : shaker_->state().time_s; }

  // The operator's controller events (control channel, --fault).
  void press_estop() noexcept;
  void latch_fault(std::uint16_t code) noexcept;
  std::string set_deadband(double mm);  // an error message for a rig without a servo
  std::string overtravel(double mm);    // the frame pushed toward mm from outside (an error for a shaker)
  // The enable command as the controller holds it: a reset drops it, and a Modbus server shows
  // that in the enable coil, so the host must write enable again.
  [[nodiscard]] protocols::Signal enable_signal() const noexcept { return frame_ ? protocols::Signal::enable : protocols::Signal::shaker_enable; }
  [[nodiscard]] bool enable_command() const noexcept;
  [[nodiscard]] std::string describe_controller() const;

 private:
  [[nodiscard]] const Controller& controller() const noexcept { return frame_ ? frame_->controller() : shaker_->controller(); }
  std::unique_ptr<LoadFrameSim> frame_;
  std::unique_ptr<ShakerSim> shaker_;
  LoadFrameCommands frame_cmd_;
  ShakerCommands shaker_cmd_;
};

}  // namespace hystlab::sim
