#pragma once
// The simulated rig as the servers see it: signal values in, signal values out, whatever the
// physics behind (load frame or shaker). Also the faults a test can inject.
#include <array>
#include <memory>
#include <optional>
#include <string>

#include "hystlab/protocols/signals.hpp"
#include "load_frame_sim.hpp"
#include "shaker_sim.hpp"

namespace hystlab::sim {

using SignalValues = std::array<double, protocols::kSignalCount>;

struct Faults {
  bool drop = false;        // close every Modbus connection and refuse new ones
  int delay_ms = 0;         // answer late, with the values of when the request came
  int stall_ms = 0;         // stop this long before each answer (physics too), like a starved process
  int exception = 0;        // answer every request with this Modbus exception code
  bool crc = false;         // RTU: corrupt the CRC of every answer
  bool freeze = false;      // the measurements (and the sample counter) stop updating
  bool overload = false;    // the force reads far beyond the load cell's range
  bool can_silent = false;  // stop sending CAN status frames
  // "drop", "delay=200", "exception=4", ...; returns an error message or "" when applied.
  std::string apply(const std::string& spec);
  [[nodiscard]] std::string describe() const;
};

class SimRig {
 public:
  explicit SimRig(std::unique_ptr<LoadFrameSim> frame) : frame_(std::move(frame)) {}
  explicit SimRig(std::unique_ptr<ShakerSim> shaker) : shaker_(std::move(shaker)) {}
  [[nodiscard]] protocols::RigKind kind() const noexcept {
    return frame_ ? protocols::RigKind::load_frame : protocols::RigKind::shaker;
  }
  void step(double dt) noexcept;
  // Command signals present in values (NaN: not given) are applied.
  void apply(const SignalValues& values) noexcept;
  // Measurements (NaN for signals this rig has not), with the overload fault applied.
  [[nodiscard]] SignalValues measurements(const Faults& faults) const noexcept;
  [[nodiscard]] double time_s() const noexcept { return frame_ ? frame_->state().time_s : shaker_->state().time_s; }

 private:
  std::unique_ptr<LoadFrameSim> frame_;
  std::unique_ptr<ShakerSim> shaker_;
  LoadFrameCommands frame_cmd_;
  double freq_ = 0, amp_ = 0;
  bool shaker_on_ = false;
};

}  // namespace hystlab::sim
