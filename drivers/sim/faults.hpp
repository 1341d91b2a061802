#pragma once
// The faults a test or an operator injects: communication faults (Faults, removed by `clear`)
// and controller events (e-stop button, latched fault, servo dead band), which act on the rig and
// stay until the controller's own reset, as on a real controller.
#include <string>

namespace hystlab::sim {

class SimRig;

struct Faults {
  bool drop = false;        // close every Modbus connection and refuse new ones
  int delay_ms = 0;         // answer late, with the values of when the request came
  int late_step_ms = 0;     // answer this late to the first write of each new drive frequency (a shaker's step)
  int stall_ms = 0;         // stop this long before each answer (physics too), like a starved process
  int exception = 0;        // answer every request with this Modbus exception code
  bool crc = false;         // RTU: corrupt the CRC of every answer
  bool freeze = false;      // the measurements (and the sample counter) stop updating
  bool overload = false;    // the force reads far beyond the load cell's range
  bool can_silent = false;  // stop sending CAN status frames
  // "drop", "delay=200", "late-step=150", "exception=4", ...; returns an error message or "" when applied.
  std::string apply(const std::string& spec);
  [[nodiscard]] std::string describe() const;
};

// spec as for Faults::apply, plus the controller events "estop", "latch[=CODE]" and
// "deadband=MM", which go to the rig. Returns an error message or "" when applied.
std::string apply_fault(const std::string& spec, Faults& faults, SimRig& rig);

}  // namespace hystlab::sim
