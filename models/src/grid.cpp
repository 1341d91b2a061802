#include "hystlab/models/grid.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hystlab::models {

Grid Grid::make(double lo, double hi, int n) {
  if (!std::isfinite(lo)) throw std::invalid_argument("grid: range start is not a finite number");
  if (!std::isfinite(hi)) throw std::invalid_argument("grid: range end is not a finite number");
  if (!(hi > lo))
    throw std::invalid_argument("grid: range end (" + std::to_string(hi) + ") must be greater than its start (" +
                                std::to_string(lo) + ")");
  if (n < 1 || n > 2000)
    throw std::invalid_argument("grid: subdivisions must be between 1 and 2000, got " + std::to_string(n));
  return Grid{lo, hi, n};
}

int Grid::node_near(double x, double tol) const noexcept {
  if (!std::isfinite(x)) return -1;
  const double u = (x - lo) / step();
  const double r = std::round(u);
  if (r < 0.0 || r > static_cast<double>(n)) return -1;
  const int i = static_cast<int>(r);
  return std::fabs(x - node(i)) <= tol ? i : -1;
}

}  // namespace hystlab::models
