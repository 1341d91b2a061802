#pragma once
// The adaptive FOT campaign's next row (issue 41), chosen from what the campaign has measured.
//
// The nodes are measured on a fine grid (the coarse grid halved 1 or more times): every descent
// passes every fine node below its top, so a row's descent is read at any node a later row adds.
// The campaign's table is that of the rows measured whole: δmin and their tops, a non-uniform grid
// (table format v2), its nodes read from the fine builder (OnlineTableBuilder::restricted).
//
// The rule is fot_design.hpp's (the offline `hystlab design` has the same): each band between two
// measured tops has an estimated error from linear interpolation across it, h²/8 times the Everett
// surface's second derivatives along the rows and along the descents (divided differences of the
// neighbouring rows and columns); the next row halves the band whose split removes the most
// estimated squared error per second of rig time (a row costs its ramps up and down at the plan's
// rate, its dwells and a settle). The estimated held-out RMS adds the force noise, which no row
// removes: est² = interpolation² + σ². It stops at the target (est ≤ target_rms_N), at the budget
// (the next row would take the rows past budget_s), when no row removes min_gain of the estimated
// squared error left, or when every band is one fine step wide, and says which.
//
// Why curvature and not the least-squares fit's σ per cell: between two rows the table is the FOT
// table of the rows measured (no fit needed, O(n²), tens of microseconds), and on an SMA spring the
// error lives where the surface bends (the plateaus' corners), which the curvature sees and σ does
// not (σ is even across a noise-free record). The noise enters as the floor of the estimate.
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "hystlab/models/fot_design.hpp"
#include "hystlab/models/online_table_builder.hpp"

namespace hystlab::models {

struct AdaptiveOptions {
  double ramp_mm_s = 0.18;  // the rows' rate
  double settle_s = 1.0;    // per row beyond its ramps: its dwells and the servo's arrival
  double budget_s = 600;    // rig seconds for all rows (those measured included)
  double target_rms_N = 0;  // 0: none
  double min_gain = 0.02;
  double noise_N = 0;  // the force noise, 1 σ (force_noise)
};

struct AdaptiveStep {
  std::optional<int> row;        // the next row's top as a fine-grid node; none: the design stops
  double alpha_mm = 0;           // its top (mm)
  double estimated_rms_N = 0;    // the table's estimated held-out RMS now (noise included)
  double spent_s = 0;            // the measured rows' rig time by the cost model
  double next_s = 0;             // the next row's (0: none)
  std::string why;               // why this row: which term of which band
  std::string stopped;           // why the design stops (empty when a row is chosen)
  std::vector<double> nodes_mm;  // the grid of the rows measured
};

// The fine rows i (1..n) with every node (i, j < i) measured, and 0 first.
[[nodiscard]] std::vector<int> measured_rows(const OnlineTableBuilder& fine);
// The table's builder: the measured rows on their own grid; empty when the top row (n) is not measured.
[[nodiscard]] std::optional<OnlineTableBuilder> rows_builder(const OnlineTableBuilder& fine);
// The next row; the design's rule above. The fine grid's top row must be measured (the coarse rows
// come first): before that the step says so and chooses none.
[[nodiscard]] AdaptiveStep next_row(const OnlineTableBuilder& fine, const AdaptiveOptions& o);
// The force noise (1 σ) of a record sampled densely along slow ramps, from second differences:
// σ² = mean((f[k+1] − 2 f[k] + f[k−1])²) / 6; the smooth part of the force cancels. The median of
// the squared differences is used (times 1/0.455, the χ²₁ median) so that turning points and
// corners do not inflate it. 0 for fewer than 3 samples.
[[nodiscard]] double force_noise(std::span<const double> f);

}  // namespace hystlab::models
