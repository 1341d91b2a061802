#pragma once
// The signals of each rig kind, named once: the API's JSON keys, the CSV headers and (for the
// shaker) the database columns all come from these tables.
#include <array>
#include <string>

namespace hystlab::domain {

struct SignalName {
  const char* name;   // with its unit: "base_displacement_mm"
  const char* label;  // for people: "base displacement (mm)"
};

// A load frame's samples (SampleRow's cmd, disp, force).
inline constexpr std::array<SignalName, 3> kFrameSignals{{{"command_mm", "command (mm)"}, {"displacement_mm", "displacement (mm)"}, {"force_N", "force (N)"}}};

// A shaker's samples (ShakerRow::v, in this order): the drive the host commanded, and the
// transducers' base and mass motion.
inline constexpr std::array<SignalName, 6> kShakerSignals{{{"drive_frequency_hz", "drive frequency (Hz)"},
                                                           {"drive_amplitude_mm", "drive amplitude (mm)"},
                                                           {"base_displacement_mm", "base displacement (mm)"},
                                                           {"mass_displacement_mm", "mass displacement (mm)"},
                                                           {"base_accel_m_s2", "base acceleration (m/s²)"},
                                                           {"mass_accel_m_s2", "mass acceleration (m/s²)"}}};
namespace shaker_signal {  // indices into ShakerRow::v
inline constexpr std::size_t drive_frequency = 0, drive_amplitude = 1, base_displacement = 2, mass_displacement = 3, base_accel = 4, mass_accel = 5;
}  // namespace shaker_signal

// The three values a rig's live sample carries (control::LiveSample's cmd, disp, force), named
// for the rig panel and the event stream.
inline constexpr std::array<const char*, 3> kLiveFrameSignals{"command_mm", "displacement_mm", "force_N"};
inline constexpr std::array<const char*, 3> kLiveShakerSignals{"base_displacement_mm", "mass_displacement_mm", "mass_accel_m_s2"};

// "seq,t_s,<names>,status"
template <std::size_t N>
std::string csv_header(const std::array<SignalName, N>& s) {
  std::string h = "seq,t_s";
  for (const SignalName& n : s) h += std::string(",") + n.name;
  return h + ",status\n";
}

}  // namespace hystlab::domain
