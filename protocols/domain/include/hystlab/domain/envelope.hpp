#pragma once
// What a rig can do and how it is supervised, from the rig's configuration (never from a plan):
// its envelope (stroke, force, speed, acceleration; a shaker's displacement, velocity,
// acceleration and frequency range) and its supervision settings (servo dead band, lag, settle
// time, the arming handshake's time limit, the controller's mode, the host heartbeat).
// A plan is checked against the envelope at submission; a plan's own limits may only tighten it.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "hystlab/domain/events.hpp"
#include "hystlab/domain/plan.hpp"

namespace hystlab::domain {

// Wall time the host may be starved without that being a servo or controller failure. Seen on
// the 2-core CI and work VMs: a 1 ms sleep loop woke up to 0.73 s late with the machine idle (p99
// 80 ms, CPU pressure 36%). Motion deadlines get this much wall time on top (x time scale), and
// a handshake (arming, reset, disable verified) at least kHandshakeFloor_s.
inline constexpr double kHostStallAllowance_s = 1.5;
inline constexpr double kHandshakeFloor_s = 1.0;

struct RigEnvelope {
  // load frame
  double stroke_min_mm = -10.0, stroke_max_mm = 10.0;  // the simulator trips at ±12 mm
  double force_max_N = 2000.0;                         // the simulator's load cell: 5000 N
  double speed_max_mm_s = 20.0;
  double accel_max_mm_s2 = 1000.0;
  // shaker
  double shaker_displacement_max_mm = 5.0;  // base amplitude
  double shaker_velocity_max_mm_s = 300.0;
  double shaker_accel_max_g = 10.0;
  double shaker_freq_min_hz = 1.0, shaker_freq_max_hz = 200.0;
};

struct SupervisionSettings {
  double in_position_mm = 0.01;     // a target counts as reached within this (the servo's dead band)
  double lag_s = 0.1;               // the rig's lag, added to every segment's expected duration
  double settle_s = 1.0;            // and a settle time
  double arm_timeout_s = 1.0;       // rig seconds for `enabled` to appear after enable
  double reset_timeout_s = 2.0;     // rig seconds for `ready` after a reset
  std::uint16_t mode = 1;           // written to the map's `mode` on arming (when it has one)
  double heartbeat_period_s = 0.1;  // the host heartbeat (when the map has one)
  double safe_rate_mm_s = 1.0;      // default safe rate (a plan may set its own, slower or not)
  double safe_timeout_s = 30.0;     // beyond the expected time, a safe ramp that has not arrived holds
};

struct RigConfigError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// Reads `envelope` and `supervision` of a rig's config entry (both optional); throws
// RigConfigError naming the field ("rigs[0].envelope.speed_mm_s must be a positive number").
[[nodiscard]] RigEnvelope parse_envelope(const nlohmann::json& j, const std::string& where, bool shaker);
[[nodiscard]] SupervisionSettings parse_supervision(const nlohmann::json& j, const std::string& where);
[[nodiscard]] nlohmann::json envelope_json(const RigEnvelope& e, bool shaker);
// The same as the campaign's "envelope" event.
[[nodiscard]] domain::EnvelopeEvent envelope_event(const RigEnvelope& e, bool shaker);
[[nodiscard]] nlohmann::json supervision_json(const SupervisionSettings& s);

// Refuses a plan the rig cannot run, with the field named and both numbers:
// "plan: ramp_rate_mm_s 500 exceeds the rig's maximum speed 20 mm/s". Returns the limits the
// safety checks use: the tighter of the plan's and the envelope's, with the derived safe
// position and rate filled in (stored with the campaign, shown by the API).
[[nodiscard]] Limits check_plan_against(const Plan& plan, const RigEnvelope& e, const SupervisionSettings& s, bool shaker);

// The limits the plan gave that the rig's envelope tightens, each in a sentence ("force limit:
// the rig's 2000 N applies (the plan asked 5000 N)"): a plan is not refused for a limit looser
// than the rig's, but the operator is told which one holds.
[[nodiscard]] std::vector<std::string> limits_tightened(const Plan& plan, const Limits& applied);

}  // namespace hystlab::domain
