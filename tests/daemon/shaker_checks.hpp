#pragma once
// What the shaker campaign tests read back from a store: a sweep's points and the base's weakest
// window (tests/daemon/test_shaker_campaign.cpp in real time, test_shaker_quality.cpp on the fake clock).
#include <algorithm>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "hystlab/db/store.hpp"

namespace hystlab::test {

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
