#include "fit_record.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hystlab::models {

void check_fit_record(std::span<const double> x, std::span<const double> y, const Grid& grid, int max_subdivisions) {
  if (x.size() != y.size()) throw std::invalid_argument("fit: displacement and force differ in length");
  if (grid.n > max_subdivisions)
    throw std::invalid_argument("fit: subdivisions must be at most " + std::to_string(max_subdivisions) + ", got " + std::to_string(grid.n));
  const std::size_t unknowns = grid.cell_count() + 1;
  if (x.size() < 2 * unknowns)
    throw std::invalid_argument("fit: " + std::to_string(x.size()) + " samples are too few for " + std::to_string(unknowns) +
                                " unknowns (need at least twice as many)");
  for (std::size_t k = 0; k < x.size(); ++k)
    if (!std::isfinite(x[k]) || !std::isfinite(y[k])) throw std::invalid_argument("fit: sample " + std::to_string(k) + " is not a finite number");
}

}  // namespace hystlab::models
