#pragma once
// The MQTT payloads (docs/LAB.md gives an example of each), as compact JSON text. Pure: the
// publisher's thread gathers the values, these only format them.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hystlab/control/values.hpp"
#include "hystlab/lab/lab_config.hpp"

namespace hystlab::lab::detail {

// UTC, ISO 8601 with milliseconds ("2026-03-01T10:22:05.123Z"), as the daemon's rows.
[[nodiscard]] std::string utc_now();

// A rig's state topic, without "changed_at" (compared to see a change).
[[nodiscard]] nlohmann::json state_json(const control::RigInfo& info, const control::RigSupervision& s, const control::AcquisitionCounters& a,
                                        std::int64_t nodes);

// One live batch: samples [first, first + n) of the rig's ring, all of one run.
struct LiveBatch {
  std::uint64_t seq = 0, first = 0, lost = 0;  // lost: samples overwritten just before `first`
  std::int64_t run = 0;
  std::vector<control::LiveSample> samples;
};
[[nodiscard]] std::string live_json(const std::string& rig, domain::RigKind kind, const LiveBatch& b);

// One row of the events table.
struct EventRow {
  std::int64_t id = 0, campaign = 0, run = 0;
  std::string at, kind, from_state, to_state, detail, rig;  // rig: the campaign's rig's name ("" when none)
  double t = 0;
  bool has_t = false;
};
[[nodiscard]] std::string event_json(const EventRow& e);

// The daemon's status: online (retained while connected), and offline (the will, or a clean stop).
[[nodiscard]] std::string status_json(const LabConfig& lab, const std::string& state, const std::string& started_at, const std::string& reason,
                                      const std::vector<std::string>& rigs);

}  // namespace hystlab::lab::detail
