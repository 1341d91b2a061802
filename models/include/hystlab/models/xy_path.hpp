#pragma once
// Decimation of an x-y path that keeps its shape: a hysteresis loop drawn from few points.
//
// Plotting libraries thin a line by pixel column, assuming x only increases; a loop's unloading
// branches then vanish (issue 12: past ~1,500 points every δ_i showed a vertical line). Pairing
// each time bucket's x minimum with its y minimum is no better: they are not one point. Here:
// - every reversal of x is kept (the input's turning points: the branches themselves, and for a
//   Preisach model the whole history that fixes its output, so a model evaluated on the kept
//   points alone gives the same force there);
// - between reversals, points are kept at equal steps of arc length in the plot's normalised
//   (x, y) space, so the budget goes where the curve goes. Motion below a small quantum does not
//   count, so noise during a dwell spends no points.
// O(n) in two passes, no allocation beyond the result.
#include <cstddef>
#include <span>
#include <vector>

namespace hystlab::models {

struct PathReduction {
  std::vector<std::size_t> index;  // kept samples, in order (first and last included)
  std::size_t reversals = 0;       // reversals of x found (each one kept)
};

// budget: points wanted (the reversals are kept beyond it when there are more). reversal_fraction:
// a turn of x counts when x comes back by this fraction of its range (noise below it is no turn).
[[nodiscard]] PathReduction reduce_path(std::span<const float> x, std::span<const float> y, std::size_t budget, double reversal_fraction = 0.01);

// The reversals of x alone (indices of the turning points), with the same rule.
[[nodiscard]] std::vector<std::size_t> reversals_of(std::span<const float> x, double threshold);

}  // namespace hystlab::models
