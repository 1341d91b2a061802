#pragma once
// Can a data set be represented by a Preisach model? The two properties that characterise it
// (Mayergoyz): wiping-out (return-point memory) and congruency of minor loops, as numbers.
#include <cstddef>
#include <span>
#include <vector>

namespace hystlab::models {

struct RepresentationOptions {
  double dead_band = -1.0;           // mm; reversals smaller than this are noise. < 0: 0.5 % of the input range
  double extremum_tolerance = -1.0;  // mm; loops whose extrema agree within it are compared. < 0: 1 % of the range
  int branch_points = 16;            // points per branch when comparing loop shapes
};

struct WipingOutReport {
  std::size_t events = 0;           // minor loops closed by returning to an earlier turning point
  double max_deviation = 0.0;       // N, |force on return - force at that turning point|
  double rms_deviation = 0.0;       // N
  double max_deviation_norm = 0.0;  // / force range
};

struct CongruencyReport {
  std::size_t loops = 0;            // closed minor loops found
  std::size_t compared_pairs = 0;   // pairs of loops with the same extrema
  double max_deviation = 0.0;       // N, largest shape difference after the vertical shift
  double rms_deviation = 0.0;       // N
  double max_deviation_norm = 0.0;  // / force range
};

struct RepresentationReport {
  std::size_t reversals = 0;
  double force_range = 0.0;
  WipingOutReport wiping_out;
  CongruencyReport congruency;
};

// Turning points of the input: indices where it reverses by more than dead_band.
[[nodiscard]] std::vector<std::size_t> find_reversals(std::span<const double> input, double dead_band);

// Throws std::invalid_argument when sizes differ or a value is not finite.
[[nodiscard]] RepresentationReport check_representation(std::span<const double> input, std::span<const double> force,
                                                        const RepresentationOptions& options = {});

}  // namespace hystlab::models
