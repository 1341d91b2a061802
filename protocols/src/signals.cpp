#include "hystlab/protocols/signals.hpp"

namespace hystlab::protocols {
namespace {
constexpr std::array<std::string_view, kSignalCount> kNames = {"setpoint_mm",
                                                               "ramp_rate_mm_s",
                                                               "enable",
                                                               "hold",
                                                               "estop",
                                                               "mode",
                                                               "drive_frequency_hz",
                                                               "drive_amplitude_mm",
                                                               "shaker_enable",
                                                               "fault_reset",
                                                               "host_heartbeat",
                                                               "displacement_mm",
                                                               "force_N",
                                                               "command_mm",
                                                               "status_word",
                                                               "fault_code",
                                                               "heartbeat",
                                                               "sample_counter",
                                                               "base_accel_m_s2",
                                                               "mass_accel_m_s2",
                                                               "base_displacement_mm",
                                                               "mass_displacement_mm"};
// A name left out would leave a trailing entry empty: every Signal must have its name.
static_assert(!kNames.back().empty(), "kNames must name every Signal, in the enum's order");
}  // namespace

std::string_view signal_name(Signal s) noexcept { return kNames[static_cast<std::size_t>(s)]; }

std::optional<Signal> signal_from_name(std::string_view name) noexcept {
  for (std::size_t k = 0; k < kSignalCount; ++k)
    if (kNames[k] == name) return static_cast<Signal>(k);
  return std::nullopt;
}

bool is_command(Signal s) noexcept { return s <= Signal::host_heartbeat; }

bool is_required(Signal s, RigKind kind) noexcept {
  switch (s) {
    case Signal::status_word:
    case Signal::fault_code:
    case Signal::heartbeat:
    case Signal::sample_counter:
    case Signal::estop:
      return true;
    case Signal::setpoint_mm:
    case Signal::ramp_rate_mm_s:
    case Signal::enable:
    case Signal::hold:
    case Signal::displacement_mm:
    case Signal::force_N:
      return kind == RigKind::load_frame;
    case Signal::drive_frequency_hz:
    case Signal::drive_amplitude_mm:
    case Signal::shaker_enable:
    case Signal::base_accel_m_s2:
    case Signal::mass_accel_m_s2:
    case Signal::base_displacement_mm:
    case Signal::mass_displacement_mm:
      return kind == RigKind::shaker;
    default:
      return false;
  }
}

}  // namespace hystlab::protocols
