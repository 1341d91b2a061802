#pragma once
// Where the next FOT rows should go (issue 41): from an identified table, the rows (tops α of a
// first-order reversal, each measured down to δmin) that remove the most of the table's estimated
// error per second of rig time, until a budget, a target or diminishing returns stops it.
//
// The rule. A row at α* inside the band [δ_k, δ_k+1] adds a node there: a new row F(α*, ·) and a new
// column F(·, α*) (read from the descents already measured, which pass through α*). What the table
// gets wrong inside a band is estimated per node of the band's midline as
//   e² = (h²/8 · |∂²F/∂α²|)² + (h²/8 · |∂²F/∂β²|)² + σ²,
// the error of interpolating linearly across a band of width h (its second derivative from the
// divided differences of the neighbouring rows and columns) plus the fit's own uncertainty of the
// band's cells (σ, when the table came from a least-squares fit; 0 for an FOT table). Splitting a
// band halves h (the curvature terms fall 4×) and adds a row of data (σ² halves). A row costs its
// ramp: up from δmin to α* and down again at the plan's rate, plus a fixed settle. The greedy choice
// takes the band whose split removes the most squared error per second; it stops when the
// estimated RMS error reaches the target, the next row would exceed the budget, or a row removes
// less than `min_gain` of what is left. Why this and not σ alone: an FOT table has no σ, and where
// the Everett surface bends (an SMA spring's transformation plateaus) the interpolation error
// dominates the noise; σ alone would spread rows evenly over a noise-free record.
#include <span>
#include <string>
#include <vector>

#include "hystlab/models/everett_table.hpp"

namespace hystlab::models {

struct DesignOptions {
  double ramp_mm_s = 0.18;    // the rows' ramp rate (a plan's rate_mm_s)
  double settle_s = 2.0;      // per row, beyond its ramps (the FOT's dwell at the top and bottom)
  double budget_s = 600.0;    // rig time for the new rows
  double target_rms_N = 0.0;  // stop when the estimated RMS error is at or below it (0: none)
  double min_gain = 0.02;     // stop when a row would remove less than this share of what is left
  double min_band_mm = 0.0;   // bands narrower than this are not split (0: 1/1000 of the range)
  int max_rows = 200;
  // The force noise (1 σ, N) of the record the table will be scored on: no row removes it, so it
  // counts in the estimated RMS error (the target and the stops) and in what a row's gain is a
  // share of. 0: the table's own error alone.
  double noise_N = 0.0;
};

struct DesignRow {
  double alpha_mm = 0.0;     // the row's top
  double seconds = 0.0;      // its rig time
  double error_N = 0.0;      // the band's estimated RMS error before it (N)
  double rms_after_N = 0.0;  // the whole table's estimated RMS error after it
  std::string why;           // which term dominated, in the user's words
};

struct Design {
  std::vector<DesignRow> rows;  // in the order chosen
  double rms_before_N = 0.0;    // the table's estimated RMS error as it is (with the noise)
  double seconds = 0.0;         // all rows' rig time
  std::vector<double> nodes;    // the grid with the rows' nodes added
  std::string stopped;          // "target", "budget", "gain" or "rows", said in words
};

// A row's rig time, the one cost model of the design (and of an adaptive campaign's budget): up
// from δmin to its top and down again at the ramp rate, plus a settle (its dwells and the servo's
// arrival at both ends).
[[nodiscard]] inline double row_seconds(double above_lo_mm, double ramp_mm_s, double settle_s) noexcept { return 2.0 * above_lo_mm / ramp_mm_s + settle_s; }

// cell_sigma: Grid::cell_index order (PreisachFitResult's), or empty. Throws std::invalid_argument
// naming the option for a budget below one row, a negative target or rate, or a σ of the wrong size.
[[nodiscard]] Design design_rows(const EverettTable& table, std::span<const double> cell_sigma, const DesignOptions& options);

}  // namespace hystlab::models
