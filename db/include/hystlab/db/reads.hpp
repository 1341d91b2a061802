#pragma once
// The rows the API and the CLI read, as value types: what they query lives here, in db/, and
// nowhere else holds SQL.
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

namespace hystlab::db {

struct RunInfo {
  std::int64_t id = 0, campaign = 0;
  std::string state, started_at, ended_at;  // ended_at empty while it runs
  double wall_anchor_unix = 0;
  std::int64_t samples = 0, nodes = 0;
  std::string role;  // campaign or validation
};

struct LoopInfo {  // one closed cycle of a run
  std::int64_t run = 0, k = 0;
  std::string phase, figures_json;
};

struct TableInfo {
  std::int64_t id = 0;
  std::optional<std::int64_t> campaign, run;
  std::string method;
  std::int64_t n = 0;
  double range_lo = 0, range_hi = 0;
  std::string created_at, accuracy_json;
};

struct NodeInfo {
  std::int64_t id = 0, campaign = 0, run = 0;
  double alpha = 0, beta = 0, force_alpha = 0, force_alpha_beta = 0, t = 0;
};

struct TransmissibilityInfo {
  std::int64_t id = 0, run = 0;
  double frequency_hz = 0, base_amplitude_mm = 0, mass_amplitude_mm = 0, ratio = 0, phase_rad = 0;
  // Since schema 5 (a sweep of several amplitudes and directions): 0, "" and NaN in older rows.
  std::int64_t step = 0;
  double demand_mm = 0;
  std::string direction, detail;  // detail: the step's whole record (JSON), "" when none
  double predicted_ratio = NAN, predicted_phase_rad = NAN;
};

struct SinePointRow {
  std::int64_t step = 0;
  double frequency_hz = 0, demand_mm = 0, base_amplitude_mm = 0, mass_amplitude_mm = 0, ratio = 0, phase_rad = 0;
  std::string direction, detail;
};

// An event with its campaign (the event stream reads them across campaigns).
struct EventInfo {
  std::int64_t id = 0, campaign = 0;
  std::string at, kind, from_state, to_state, detail;
};

}  // namespace hystlab::db
