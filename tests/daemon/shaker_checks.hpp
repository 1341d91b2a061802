#pragma once
// What the shaker campaign tests read back from a store: a sweep's points and the base's weakest
// window (tests/daemon/test_shaker_campaign.cpp in real time, test_shaker_quality.cpp on the fake clock).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <numbers>
#include <vector>

#include "hystlab/db/store.hpp"
#include "hystlab/models/sdof.hpp"

namespace hystlab::test {

// The simulator's isolator (hystlab-sim --rig shaker), linearised: 13 kg on 4 springs of 40 N/mm
// (the SMA springs' elastic line, or hystlab-sim --linear 40), 58 N·s/m.
inline constexpr double kIsolatorK = 4 * 40e3, kIsolatorC = 58, kIsolatorM = 13;

// Its transmissibility |X/Y| at f Hz.
inline double linear_ratio(double f) {
  const double fn = std::sqrt(kIsolatorK / kIsolatorM) / (2 * std::numbers::pi), zeta = kIsolatorC / (2 * std::sqrt(kIsolatorK * kIsolatorM));
  return models::linear_transmissibility(f / fn, zeta);
}

// The phase of X/Y = (k + icω)/(k − mω² + icω), in the fit's convention (mass minus base).
inline double linear_phase(double f) {
  const double w = 2 * std::numbers::pi * f;
  return std::atan2(kIsolatorC * w, kIsolatorK) - std::atan2(kIsolatorC * w, kIsolatorK - kIsolatorM * w * w);
}

// The plans both the real-time tests (test_shaker_campaign.cpp) and the fake clock's
// (test_shaker_quality.cpp) run: the same plan, its figures printed in one and checked in the other.
// Three steps at 0.005 mm, settled by the mass's amplitude, a 3 % control tolerance (the SMA springs' test).
inline nlohmann::json sma_steps_plan() {
  return {{"kind", "sine"},
          {"frequencies_hz", {12, 30, 60}},
          {"amplitude_mm", 0.005},
          {"settle", {{"change", "1 %"}, {"consecutive", 3}}},
          {"measured_cycles", 8},
          {"sample_rate_hz", 1000},
          {"control", {{"tolerance", "3 %"}, {"window_cycles", 3}}}};
}

// Three steps at 0.05 mm, where SMA springs would transform and linear ones keep the curve analytic.
inline nlohmann::json linear_large_plan() {
  return {{"kind", "sine"},       {"frequencies_hz", {12, 16, 30}}, {"amplitude_mm", 0.05}, {"settle", {{"change", "1 %"}, {"consecutive", 3}}},
          {"measured_cycles", 8}, {"sample_rate_hz", 1000}};
}

// A resonance dwell from 16 Hz, tracking -90 degrees within 5 for 300 cycles.
inline nlohmann::json dwell_plan() {
  return {{"kind", "sine"},        {"dwell", {{"frequency_hz", 16}, {"cycles", 300}, {"track", "phase"}, {"phase_deg", -90}, {"tolerance_deg", 5}}},
          {"amplitude_mm", 0.005}, {"settle_cycles", 20},
          {"measured_cycles", 10}, {"sample_rate_hz", 1000}};
}

// Amplitude levels 0.005 -> 0.05 -> 0.005 mm at 10 Hz.
inline nlohmann::json ramp_plan() {
  return {{"kind", "sine"},      {"frequencies_hz", {10}}, {"amplitudes_mm", {0.005, 0.05, 0.005}},
          {"settle_cycles", 10}, {"measured_cycles", 8},   {"sample_rate_hz", 1000}};
}

// A continuous sweep from 8 to 11 Hz at 1.5 Hz/s, a point every 4 cycles.
inline nlohmann::json slow_sweep_plan() {
  return {{"kind", "sine"},        {"sweep", {{"from_hz", 8}, {"to_hz", 11}, {"rate_hz_s", 1.5}}},
          {"amplitude_mm", 0.005}, {"settle_cycles", 20},
          {"measured_cycles", 4},  {"sample_rate_hz", 1000}};
}

// Four coarse steps either side of the isolator's peak, refined until 5 points lie in its half-power band.
inline nlohmann::json refinement_plan() {
  return {{"kind", "sine"},
          {"frequencies_hz", {8, 12, 25, 40}},
          {"amplitude_mm", 0.005},
          {"settle", {{"change", "1 %"}, {"consecutive", 2}, {"min_cycles", 15}}},
          {"measured_cycles", 8},
          {"sample_rate_hz", 1000},
          {"resonance", {{"half_power_points", 5}, {"max_steps", 30}}}};
}

// Where the mass lags its base by 90 degrees (bisection on linear_phase between 15 and 20 Hz).
inline double linear_quadrature_hz() {
  double lo = 15, hi = 20;
  for (int i = 0; i < 60; ++i) (linear_phase(0.5 * (lo + hi)) > -std::numbers::pi / 2 ? lo : hi) = 0.5 * (lo + hi);
  return 0.5 * (lo + hi);
}

inline std::vector<nlohmann::json> points_of(db::Store& store, std::int64_t campaign) {
  std::vector<nlohmann::json> out;
  for (const db::TransmissibilityInfo& t : store.transmissibility(campaign)) {
    nlohmann::json j = nlohmann::json::parse(t.detail);
    j["predicted_ratio"] = t.predicted_ratio;
    out.push_back(j);
  }
  return out;
}

// The base's amplitude, half its peak-to-peak, in consecutive windows of `window_s` from t0 to t1:
// the smallest one over ratio to the demand (a window at least one period of the lowest frequency).
inline double weakest_base_window(db::Store& store, std::int64_t run, double t0, double t1, double window_s, double demand_mm) {
  double lo = 1e9, hi = -1e9, start = t0, weakest = 1e9;
  store.for_each_shaker_sample(run, 0, 1 << 30, [&](const db::ShakerRow& row) {
    if (row.t < t0 || row.t > t1) return;
    if (row.t - start > window_s) {
      weakest = std::min(weakest, (hi - lo) / 2 / demand_mm);
      lo = 1e9, hi = -1e9, start = row.t;
    }
    lo = std::min(lo, row.v.base_displacement_mm), hi = std::max(hi, row.v.base_displacement_mm);
  });
  return weakest;
}

}  // namespace hystlab::test
