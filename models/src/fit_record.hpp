#pragma once
// The checks every least-squares fit makes of its record (private to hystlab::models): the same
// words for the dense fit and the matrix-free one.
#include <span>

#include "hystlab/models/grid.hpp"

namespace hystlab::models {

// Throws std::invalid_argument when the columns differ in length, n is above max_subdivisions,
// there are fewer than twice as many samples as unknowns, or a sample is not finite.
void check_fit_record(std::span<const double> x, std::span<const double> y, const Grid& grid, int max_subdivisions);

}  // namespace hystlab::models
