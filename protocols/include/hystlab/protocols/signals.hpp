#pragma once
// The signals a rig exchanges with hystlab, whatever the protocol carries them.
#include <array>
#include <cstddef>
#include <optional>
#include <string_view>

#include "hystlab/domain/campaign.hpp"

namespace hystlab::protocols {

enum class Signal : std::size_t {
  // commands (written by hystlab)
  setpoint_mm,
  ramp_rate_mm_s,
  enable,
  hold,
  estop,
  mode,
  drive_frequency_hz,
  drive_amplitude_mm,
  shaker_enable,
  fault_reset,     // a rising edge clears the controller's latched faults (optional)
  host_heartbeat,  // a counter the host keeps changing; a controller may stop when it stalls (optional)
  // measurements (read by hystlab)
  displacement_mm,
  force_N,
  command_mm,  // the actuator command the controller is following
  status_word,
  fault_code,
  heartbeat,
  sample_counter,
  base_accel_m_s2,
  mass_accel_m_s2,
  base_displacement_mm,
  mass_displacement_mm,
  count_
};
inline constexpr std::size_t kSignalCount = static_cast<std::size_t>(Signal::count_);

using RigKind = domain::RigKind;  // the domain's

[[nodiscard]] std::string_view signal_name(Signal s) noexcept;
[[nodiscard]] std::optional<Signal> signal_from_name(std::string_view name) noexcept;
[[nodiscard]] bool is_command(Signal s) noexcept;
// Signals a map for this kind of rig must carry.
[[nodiscard]] bool is_required(Signal s, RigKind kind) noexcept;

// Status word bits, the same on every transport.
namespace status {
inline constexpr unsigned ready = 1U << 0;
inline constexpr unsigned enabled = 1U << 1;
inline constexpr unsigned holding = 1U << 2;
inline constexpr unsigned estop = 1U << 3;
inline constexpr unsigned limit_tripped = 1U << 4;
inline constexpr unsigned fault = 1U << 5;
inline constexpr unsigned moving = 1U << 6;
}  // namespace status

}  // namespace hystlab::protocols
