#pragma once
// The rig signals over CAN (classic frames, little-endian scaled integers). The table of
// identifiers and layouts is protocols/CAN.md; protocols/hystlab.dbc says the same for tools.
#include <linux/can.h>

#include <cstdint>
#include <system_error>
#include <variant>

#include "hystlab/protocols/protocol_error.hpp"

namespace hystlab::protocols::can {

inline constexpr std::uint32_t kCommand = 0x200, kStatusA = 0x180, kStatusB = 0x280, kStatusC = 0x380, kShakerCommand = 0x300, kShakerStatus = 0x480,
                               kHeartbeat = 0x700;
inline constexpr int kMaxMode = 3;

struct Command {  // hystlab -> rig
  double setpoint_mm = 0, ramp_rate_mm_s = 0;
  bool enable = false, hold = false, estop = false;
  std::uint8_t mode = 0;
  bool fault_reset = false;  // flag bit 3: a rising edge clears the rig's latched faults
};
struct StatusA {  // rig -> hystlab, cyclic
  double displacement_mm = 0, force_N = 0;
};
struct StatusB {
  double command_mm = 0;
  std::uint16_t status_word = 0, fault_code = 0;
};
struct StatusC {
  std::uint32_t sample_counter = 0;
};
struct Heartbeat {
  std::uint8_t counter = 0;
};
struct ShakerCommand {
  double frequency_hz = 0, amplitude_mm = 0;
  bool enable = false;
};
struct ShakerStatus {
  double base_accel_m_s2 = 0, mass_accel_m_s2 = 0, base_displacement_mm = 0, mass_displacement_mm = 0;
};

using Message = std::variant<Command, StatusA, StatusB, StatusC, Heartbeat, ShakerCommand, ShakerStatus>;

// node: 1..127, added to the base identifier.
std::error_code encode(const Message& m, int node, can_frame& out) noexcept;
std::error_code decode(const can_frame& in, int node, Message& out) noexcept;

}  // namespace hystlab::protocols::can
