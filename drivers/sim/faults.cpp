#include "faults.hpp"

#include <cmath>
#include <sstream>

#include "sim_rig.hpp"

namespace hystlab::sim {

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
  if (name == "drop")
    drop = true;
  else if (name == "delay")
    delay_ms = value > 0 ? value : 200;
  else if (name == "late-step")
    late_step_ms = value > 0 ? value : 150;
  else if (name == "stall")
    stall_ms = value > 0 ? value : 30;
  else if (name == "exception")
    exception = value > 0 ? value : 4;
  else if (name == "crc")
    crc = true;
  else if (name == "freeze")
    freeze = true;
  else if (name == "overload")
    overload = true;
  else if (name == "can-silent")
    can_silent = true;
  else if (name == "clear")
    *this = Faults{};
  else
    return "unknown fault '" + name +
           "' (drop, delay=MS, late-step=MS, stall=MS, exception=CODE, crc, freeze, overload, can-silent, estop, latch=CODE, deadband=MM, overtravel=MM, "
           "clear)";
  return "";
}

std::string Faults::describe() const {
  std::ostringstream s;
  s << "drop=" << drop << " delay=" << delay_ms << " late-step=" << late_step_ms << " stall=" << stall_ms << " exception=" << exception << " crc=" << crc
    << " freeze=" << freeze << " overload=" << overload << " can-silent=" << can_silent;
  return s.str();
}

std::string apply_fault(const std::string& spec, Faults& faults, SimRig& rig) {
  const auto eq = spec.find('=');
  const std::string name = spec.substr(0, eq);
  const std::string value = eq == std::string::npos ? "" : spec.substr(eq + 1);
  if (name == "estop") {
    rig.press_estop();
    return "";
  }
  if (name == "latch") {  // a controller fault with its code, as a drive reports one
    long code = kOperatorLatch;
    std::size_t used = 0;
    try {
      if (!value.empty()) code = std::stol(value, &used);
    } catch (...) {
      used = 0;
    }
    if (!value.empty() && (used != value.size() || code < 1 || code > 65535))
      return "fault 'latch': code '" + value + "' must be a whole number from 1 to 65535";
    rig.latch_fault(static_cast<std::uint16_t>(code));
    return "";
  }
  if (name == "deadband") {
    double mm = -1;
    std::size_t used = 0;
    try {
      mm = std::stod(value, &used);
    } catch (...) {
      used = 0;
    }
    if (value.empty() || used != value.size() || !(mm >= 0) || !std::isfinite(mm)) return "fault 'deadband': '" + value + "' must be a number of mm >= 0";
    return rig.set_deadband(mm);
  }
  if (name == "overtravel") {
    double mm = 0;
    std::size_t used = 0;
    try {
      mm = std::stod(value, &used);
    } catch (...) {
      used = 0;
    }
    if (value.empty() || used != value.size() || !std::isfinite(mm) || std::fabs(mm) > 100)
      return "fault 'overtravel': '" + value + "' must be a position in mm (within ±100)";
    return rig.overtravel(mm);
  }
  return faults.apply(spec);
}

}  // namespace hystlab::sim
