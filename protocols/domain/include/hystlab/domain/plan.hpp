#pragma once
// Campaign plans (JSON, validated at submission; an error names the field and the reason).
//   {"kind": "fot", "range_mm": [0, 4], "subdivisions": 12, "ramp_rate_mm_s": 0.5, "dwell_s": 0.2,
//    "sample_rate_hz": 1000, "repeats": 1, "training_cycles": 2,
//    "limits": {"displacement_mm": [-0.5, 4.5], "force_N": 300, "rate_mm_s": 5}}
//   FOT plans may also say how to train the specimen, validate the tables and read its loops:
//    "training": {"max_cycles": 40, "until": {"peak_force_change": "0.5 %", "energy_change": "2 %", "consecutive": 3}}
//      (major loops until both cycle-to-cycle changes stay below their thresholds for that many
//      cycles; "training_cycles": N is a fixed count, the same as {"max_cycles": N} without until;
//      a threshold is a percentage, as a number or a string with %)
//    "validation": {"reversals": 12, "range_mm": [0, 4], "rate_mm_s": 0.5, "seed": 1} or false
//      (default on: after the rows, a seeded random reversal sequence, stored as its own run, on
//      which every table of the campaign is scored)
//    "plateaus_mm": [1, 3] (the loop figures' plateau forces are read at these displacements)
//    "nodes_mm": [0, 1, 1.5, 1.75, 2, 2.25, 2.5, 3, 4] instead of range_mm and subdivisions: a grid
//      of its own, refined where accuracy is needed (table format version 2)
//    "design": {"kind": "adaptive", "budget_s": 400, "target_rms_N": 0.3, "min_gain": 0.02,
//      "finest_subdivisions": 48}: subdivisions are the coarse rows; after them the daemon chooses
//      each next row where the table is least certain (models/adaptive_fot.hpp) until the target,
//      the budget or diminishing returns; the tops lie on the finest grid ("uniform": no design)
//   {"kind": "waveform", "points_mm": [0, 2, 1, 3, 0], "ramp_rate_mm_s": 0.5, ...}
//   {"kind": "sine", "sweep": {"from_hz": 5, "to_hz": 80, "steps": 24}, "direction": "up-down", "amplitudes_mm": [0.01, 0.1]}
//     (the whole form in sine_plan.hpp)
// Times are rig time (a simulated rig's time scale is applied by the daemon).
#include <cstdint>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "hystlab/domain/campaign.hpp"
#include "hystlab/domain/plan_error.hpp"
#include "hystlab/domain/sine_plan.hpp"
#include "hystlab/models/grid.hpp"

namespace hystlab::domain {

struct Limits {
  double displacement_min_mm = -1.0, displacement_max_mm = 10.0;
  double force_max_N = 1000.0;  // |force|
  double rate_max_mm_s = 20.0;  // measured |velocity|
  double safe_position_mm = 0.0, safe_rate_mm_s = 1.0;
};

struct Training {
  int max_cycles = 0;  // major loops δmin → δmax → δmin before the rows
  bool until = false;  // stop early once the loop is stable (below)
  double peak_force_change_pct = 0.5, energy_change_pct = 2.0;
  int consecutive = 3;
};

struct Validation {
  bool enabled = false;
  int reversals = 12;
  double lo_mm = 0, hi_mm = 0, rate_mm_s = 0.5;
  std::uint64_t seed = 1;
};

// An adaptive FOT campaign's design (issue 41); adaptive false: every row of the plan's grid.
struct Design {
  bool adaptive = false;
  int finest_subdivisions = 0;  // the rows' tops lie on this grid: the coarse one halved 1 or more times
  double budget_s = 0;          // rig seconds for the rows, the coarse ones included (training, validation not)
  double target_rms_N = 0;      // stop at this estimated held-out RMS (0: none)
  double min_gain = 0.02;       // stop when no row would remove this share of the estimated error left
};

struct Plan {
  domain::CampaignKind kind = domain::CampaignKind::fot;
  // fot
  double lo_mm = 0, hi_mm = 0;
  int subdivisions = 0, repeats = 1;
  std::vector<double> nodes_mm;  // a grid of its own (n + 1 nodes over range_mm); empty: uniform
  Training training;
  Validation validation;
  std::vector<double> plateaus_mm;
  Design design;
  // waveform
  std::vector<double> points_mm;
  // sine (shaker: stepped or continuous sweeps, closed-loop base amplitude)
  SinePlan sine;
  // common
  double ramp_rate_mm_s = 0.5, dwell_s = 0.0, sample_rate_hz = 1000.0;
  Limits limits;
  nlohmann::json source;  // the plan as submitted
};

[[nodiscard]] Plan parse_plan(const nlohmann::json& j);  // throws PlanError

// A fot plan's grid: subdivisions equal steps of range_mm, or its nodes_mm.
[[nodiscard]] models::Grid fot_grid(const Plan& p);
// The grid a fot campaign's nodes are measured on: fot_grid, or an adaptive design's finest grid.
[[nodiscard]] models::Grid node_grid(const Plan& p);
// The rig seconds the design's cost model gives a row with its top `above_mm` over δmin: up and
// down at the plan's rate, the dwell at each end and kRowSettle_s (the servo's arrival in position
// at both ends; models/adaptive_fot.hpp).
[[nodiscard]] double row_seconds(const Plan& p, double above_mm);
inline constexpr double kRowSettle_s = 1.0;
// An adaptive design's finest step at least (mm): a quarter of it above the default in-position
// tolerance (0.01 mm), within which a row's top and bottom are read.
inline constexpr double kMinFineStep_mm = 0.05;

}  // namespace hystlab::domain
