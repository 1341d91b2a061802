#pragma once
// The signals of each rig kind, named once: the API's JSON keys, the CSV headers and (for the
// shaker) the database columns all come from these tables.
#include <array>
#include <string>

#include "hystlab/domain/campaign.hpp"

namespace hystlab::domain {

struct SignalName {
  const char* name;   // with its unit: "base_displacement_mm"
  const char* label;  // for people: "base displacement (mm)"
};

// A load frame's samples (SampleRow's cmd, disp, force; FrameSample below).
inline constexpr std::array<SignalName, 3> kFrameSignals{{{"command_mm", "command (mm)"}, {"displacement_mm", "displacement (mm)"}, {"force_N", "force (N)"}}};

// A shaker's samples (ShakerSample below, in this order): the drive the host commanded, and the
// transducers' base and mass motion.
inline constexpr std::array<SignalName, 6> kShakerSignals{{{"drive_frequency_hz", "drive frequency (Hz)"},
                                                           {"drive_amplitude_mm", "drive amplitude (mm)"},
                                                           {"base_displacement_mm", "base displacement (mm)"},
                                                           {"mass_displacement_mm", "mass displacement (mm)"},
                                                           {"base_accel_m_s2", "base acceleration (m/s²)"},
                                                           {"mass_accel_m_s2", "mass acceleration (m/s²)"}}};
// A load frame's sample values, by name (kFrameSignals).
struct FrameSample {
  double command_mm = 0, displacement_mm = 0, force_N = 0;
};

// A shaker's sample values, by name (kShakerSignals).
struct ShakerSample {
  double drive_frequency_hz = 0, drive_amplitude_mm = 0, base_displacement_mm = 0, mass_displacement_mm = 0, base_accel_m_s2 = 0, mass_accel_m_s2 = 0;
};
// In the order of kShakerSignals: the database's columns, the CSV's, the HDF5 datasets.
[[nodiscard]] constexpr std::array<double, 6> values(const ShakerSample& s) noexcept {
  return {s.drive_frequency_hz, s.drive_amplitude_mm, s.base_displacement_mm, s.mass_displacement_mm, s.base_accel_m_s2, s.mass_accel_m_s2};
}
[[nodiscard]] constexpr ShakerSample shaker_sample(const std::array<double, 6>& v) noexcept { return {v[0], v[1], v[2], v[3], v[4], v[5]}; }

// What a rig's live sample carries (the rig panel, the event stream): three values, a load
// frame's FrameSample, or a shaker's LiveShaker (its motion, without the drive).
struct LiveShaker {
  double base_displacement_mm = 0, mass_displacement_mm = 0, mass_accel_m_s2 = 0;
};
inline constexpr std::array<const char*, 3> kLiveFrameSignals{"command_mm", "displacement_mm", "force_N"};
inline constexpr std::array<const char*, 3> kLiveShakerSignals{"base_displacement_mm", "mass_displacement_mm", "mass_accel_m_s2"};
// The names of a rig kind's three live values, in order.
[[nodiscard]] constexpr const std::array<const char*, 3>& live_signals(RigKind k) noexcept {
  return k == RigKind::shaker ? kLiveShakerSignals : kLiveFrameSignals;
}

// "seq,t_s,<names>,status"
template <std::size_t N>
std::string csv_header(const std::array<SignalName, N>& s) {
  std::string h = "seq,t_s";
  for (const SignalName& n : s) h += std::string(",") + n.name;
  return h + ",status\n";
}

}  // namespace hystlab::domain
