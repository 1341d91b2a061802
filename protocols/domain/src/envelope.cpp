#include "hystlab/domain/envelope.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace hystlab::domain {
namespace {
using nlohmann::json;

std::string num(double v) {  // short, as a person writes it: 20, 0.5, 1.5e+04
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}
[[noreturn]] void bad(const std::string& field, const std::string& why) { throw RigConfigError("config: " + field + " " + why); }

double positive(const json& j, const char* f, double def, const std::string& where) {
  if (!j.contains(f)) return def;
  if (!j[f].is_number() || !std::isfinite(j[f].get<double>()) || !(j[f].get<double>() > 0)) bad(where + "." + f, "must be a positive number");
  return j[f].get<double>();
}
std::pair<double, double> range(const json& j, const char* f, std::pair<double, double> def, const std::string& where) {
  if (!j.contains(f)) return def;
  const json& v = j[f];
  if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number() || !(v[1].get<double>() > v[0].get<double>()))
    bad(where + "." + f, "must be [low, high] with low < high");
  return {v[0].get<double>(), v[1].get<double>()};
}
void known(const json& j, const std::string& where, std::initializer_list<const char*> names) {
  if (!j.is_object()) bad(where, "must be an object");
  for (const auto& [k, _] : j.items()) {
    bool ok = false;
    std::string list;
    for (const char* n : names) ok = ok || k == n, list += (list.empty() ? "" : ", ") + std::string(n);
    if (!ok) bad(where + "." + k, "is not a known field (" + list + ")");
  }
}
[[noreturn]] void refuse(const std::string& field, const std::string& why) { throw PlanError(field, "plan: " + field + " " + why); }
}  // namespace

RigEnvelope parse_envelope(const json& j, const std::string& where, bool shaker) {
  RigEnvelope e;
  if (j.is_null()) return e;
  if (shaker) {
    known(j, where, {"displacement_mm", "velocity_mm_s", "accel_g", "frequency_hz"});
    e.shaker_displacement_max_mm = positive(j, "displacement_mm", e.shaker_displacement_max_mm, where);
    e.shaker_velocity_max_mm_s = positive(j, "velocity_mm_s", e.shaker_velocity_max_mm_s, where);
    e.shaker_accel_max_g = positive(j, "accel_g", e.shaker_accel_max_g, where);
    std::tie(e.shaker_freq_min_hz, e.shaker_freq_max_hz) = range(j, "frequency_hz", {e.shaker_freq_min_hz, e.shaker_freq_max_hz}, where);
    if (e.shaker_freq_min_hz <= 0) bad(where + ".frequency_hz", "must start above 0 Hz");
    return e;
  }
  known(j, where, {"stroke_mm", "force_N", "speed_mm_s", "accel_mm_s2"});
  std::tie(e.stroke_min_mm, e.stroke_max_mm) = range(j, "stroke_mm", {e.stroke_min_mm, e.stroke_max_mm}, where);
  e.force_max_N = positive(j, "force_N", e.force_max_N, where);
  e.speed_max_mm_s = positive(j, "speed_mm_s", e.speed_max_mm_s, where);
  e.accel_max_mm_s2 = positive(j, "accel_mm_s2", e.accel_max_mm_s2, where);
  return e;
}

SupervisionSettings parse_supervision(const json& j, const std::string& where) {
  SupervisionSettings s;
  if (j.is_null()) return s;
  known(j, where, {"in_position_mm", "lag_s", "settle_s", "arm_timeout_s", "reset_timeout_s", "mode", "heartbeat_ms", "safe_rate_mm_s", "safe_timeout_s"});
  s.in_position_mm = positive(j, "in_position_mm", s.in_position_mm, where);
  s.lag_s = positive(j, "lag_s", s.lag_s, where);
  s.settle_s = positive(j, "settle_s", s.settle_s, where);
  s.arm_timeout_s = positive(j, "arm_timeout_s", s.arm_timeout_s, where);
  s.reset_timeout_s = positive(j, "reset_timeout_s", s.reset_timeout_s, where);
  s.heartbeat_period_s = positive(j, "heartbeat_ms", s.heartbeat_period_s * 1000, where) / 1000;
  s.safe_rate_mm_s = positive(j, "safe_rate_mm_s", s.safe_rate_mm_s, where);
  s.safe_timeout_s = positive(j, "safe_timeout_s", s.safe_timeout_s, where);
  if (j.contains("mode")) {
    if (!j["mode"].is_number_integer() || j["mode"].get<long long>() < 0 || j["mode"].get<long long>() > 65535)
      bad(where + ".mode", "must be a whole number from 0 to 65535 (the controller's mode register)");
    s.mode = j["mode"].get<std::uint16_t>();
  }
  return s;
}

domain::EnvelopeEvent envelope_event(const RigEnvelope& e, bool shaker) {
  domain::EnvelopeEvent v;
  if (shaker) {
    v.displacement_mm = e.shaker_displacement_max_mm, v.velocity_mm_s = e.shaker_velocity_max_mm_s, v.accel_g = e.shaker_accel_max_g;
    v.frequency_hz = {e.shaker_freq_min_hz, e.shaker_freq_max_hz};
  } else {
    v.stroke_mm = {e.stroke_min_mm, e.stroke_max_mm};
    v.force_N = e.force_max_N, v.speed_mm_s = e.speed_max_mm_s, v.accel_mm_s2 = e.accel_max_mm_s2;
  }
  return v;
}

json envelope_json(const RigEnvelope& e, bool shaker) { return domain::detail_json(envelope_event(e, shaker)); }

json supervision_json(const SupervisionSettings& s) {
  return {{"in_position_mm", s.in_position_mm},
          {"lag_s", s.lag_s},
          {"settle_s", s.settle_s},
          {"arm_timeout_s", s.arm_timeout_s},
          {"reset_timeout_s", s.reset_timeout_s},
          {"mode", s.mode},
          {"heartbeat_ms", s.heartbeat_period_s * 1000},
          {"safe_rate_mm_s", s.safe_rate_mm_s},
          {"safe_timeout_s", s.safe_timeout_s}};
}

namespace {
// The highest amplitude at the highest frequency is the plan's peak velocity and acceleration
// (the base amplitude is held at the demand in closed loop; the drive may be larger).
void check_shaker(const Plan& p, const RigEnvelope& e) {
  const SinePlan& s = p.sine;
  const double a = s.max_amplitude_mm(), lo = s.lowest_hz(), hi = s.highest_hz(), w = 2 * std::numbers::pi * hi;
  const std::string amp = p.source.contains("amplitudes_mm") ? "amplitudes_mm" : "amplitude_mm";
  const std::string freq = p.source.contains("frequencies_hz") ? "frequencies_hz" : s.dwell.on ? "dwell.frequency_hz" : "sweep";
  if (a > e.shaker_displacement_max_mm) refuse(amp, num(a) + " mm exceeds the shaker's maximum displacement " + num(e.shaker_displacement_max_mm) + " mm");
  for (const double f : {lo, hi})
    if (f < e.shaker_freq_min_hz * (1 - 1e-9) || f > e.shaker_freq_max_hz * (1 + 1e-9))
      refuse(freq, num(f) + " Hz is outside the shaker's range " + num(e.shaker_freq_min_hz) + "–" + num(e.shaker_freq_max_hz) + " Hz");
  if (w * a > e.shaker_velocity_max_mm_s)
    refuse(freq, num(hi) + " Hz at " + num(a) + " mm needs a peak velocity of " + num(w * a) + " mm/s; the shaker's maximum is " +
                     num(e.shaker_velocity_max_mm_s) + " mm/s");
  const double g = w * w * a / 9806.65;
  if (g > e.shaker_accel_max_g)
    refuse(freq,
           num(hi) + " Hz at " + num(a) + " mm needs a peak acceleration of " + num(g) + " g; the shaker's maximum is " + num(e.shaker_accel_max_g) + " g");
}

void check_frame(const Plan& p, const RigEnvelope& e) {
  const std::string stroke = "[" + num(e.stroke_min_mm) + ", " + num(e.stroke_max_mm) + "] mm";
  if (p.kind == domain::CampaignKind::fot && (p.lo_mm < e.stroke_min_mm || p.hi_mm > e.stroke_max_mm))
    refuse("range_mm", "[" + num(p.lo_mm) + ", " + num(p.hi_mm) + "] exceeds the rig's stroke " + stroke);
  for (std::size_t k = 0; k < p.points_mm.size(); ++k)
    if (p.points_mm[k] < e.stroke_min_mm || p.points_mm[k] > e.stroke_max_mm)
      refuse("points_mm[" + std::to_string(k) + "]", num(p.points_mm[k]) + " lies outside the rig's stroke " + stroke);
  if (p.ramp_rate_mm_s > e.speed_max_mm_s)
    refuse("ramp_rate_mm_s", num(p.ramp_rate_mm_s) + " exceeds the rig's maximum speed " + num(e.speed_max_mm_s) + " mm/s");
  const json lim = p.source.value("limits", json::object());
  if (lim.is_object() && lim.contains("safe_rate_mm_s") && p.limits.safe_rate_mm_s > e.speed_max_mm_s)
    refuse("limits.safe_rate_mm_s", num(p.limits.safe_rate_mm_s) + " exceeds the rig's maximum speed " + num(e.speed_max_mm_s) + " mm/s");
  if (p.limits.safe_position_mm < e.stroke_min_mm || p.limits.safe_position_mm > e.stroke_max_mm)
    refuse("limits.safe_position_mm", num(p.limits.safe_position_mm) + " lies outside the rig's stroke " + stroke);
}
}  // namespace

std::vector<std::string> limits_tightened(const Plan& p, const Limits& a) {
  std::vector<std::string> out;
  const json lim = p.source.value("limits", json::object());
  auto given = [&](const char* k) { return lim.is_object() && lim.contains(k); };
  const Limits& asked = p.limits;
  if (given("force_N") && asked.force_max_N > a.force_max_N)
    out.push_back("force limit: the rig's " + num(a.force_max_N) + " N applies (the plan asked " + num(asked.force_max_N) + " N)");
  if (given("rate_mm_s") && asked.rate_max_mm_s > a.rate_max_mm_s)
    out.push_back("rate limit: the rig's " + num(a.rate_max_mm_s) + " mm/s applies (the plan asked " + num(asked.rate_max_mm_s) + " mm/s)");
  if (given("displacement_mm") && (asked.displacement_min_mm < a.displacement_min_mm || asked.displacement_max_mm > a.displacement_max_mm))
    out.push_back("displacement limits: " + num(a.displacement_min_mm) + " to " + num(a.displacement_max_mm) +
                  " mm apply, within the rig's stroke (the plan asked " + num(asked.displacement_min_mm) + " to " + num(asked.displacement_max_mm) + " mm)");
  return out;
}

Limits check_plan_against(const Plan& p, const RigEnvelope& e, const SupervisionSettings& s, bool shaker) {
  Limits l = p.limits;
  if (shaker) {
    check_shaker(p, e);
    l.displacement_max_mm = std::min(l.displacement_max_mm, 2 * e.shaker_displacement_max_mm + 1);  // the mass's excursion
    l.displacement_min_mm = -l.displacement_max_mm;
    return l;
  }
  check_frame(p, e);
  const json lim = p.source.value("limits", json::object());
  const bool own_safe_rate = lim.is_object() && lim.contains("safe_rate_mm_s");
  l.displacement_min_mm = std::max(l.displacement_min_mm, e.stroke_min_mm);
  l.displacement_max_mm = std::min(l.displacement_max_mm, e.stroke_max_mm);
  l.force_max_N = std::min(l.force_max_N, e.force_max_N);
  l.rate_max_mm_s = std::min(l.rate_max_mm_s, e.speed_max_mm_s);
  if (!own_safe_rate) l.safe_rate_mm_s = std::min(s.safe_rate_mm_s, e.speed_max_mm_s);
  // A ramp must fit under the rate limit that trips it (with room for the servo's overshoot).
  if (p.ramp_rate_mm_s > l.rate_max_mm_s) refuse("ramp_rate_mm_s", num(p.ramp_rate_mm_s) + " exceeds the rate limit " + num(l.rate_max_mm_s) + " mm/s");
  if (p.validation.enabled && p.validation.rate_mm_s > l.rate_max_mm_s)
    refuse("validation.rate_mm_s", num(p.validation.rate_mm_s) + " exceeds the rate limit " + num(l.rate_max_mm_s) + " mm/s");
  return l;
}

}  // namespace hystlab::domain
