#include "hystlab/models/everett_table.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hystlab::models {

EverettTable::EverettTable(Grid grid)
    : grid_(grid), inv_step_(1.0 / grid.step()), nodes_(grid.positions ? grid.positions->data() : nullptr), values_(grid.node_count(), 0.0) {}

EverettTable::EverettTable(Grid grid, std::vector<double> values, double force_offset)
    : grid_(grid),
      inv_step_(1.0 / grid.step()),
      nodes_(grid.positions ? grid.positions->data() : nullptr),
      values_(std::move(values)),
      force_offset_(force_offset) {
  if (values_.size() != grid_.node_count())
    throw std::invalid_argument("table: expected " + std::to_string(grid_.node_count()) + " values for n = " + std::to_string(grid_.n) + ", got " +
                                std::to_string(values_.size()));
  if (!std::isfinite(force_offset)) throw std::invalid_argument("table: force offset is not a finite number");
  double scale = 0.0;
  for (std::size_t k = 0; k < values_.size(); ++k) {
    if (!std::isfinite(values_[k])) throw std::invalid_argument("table: value " + std::to_string(k) + " is not finite");
    scale = std::max(scale, std::fabs(values_[k]));
  }
  for (int i = 0; i <= grid_.n; ++i) {
    double& d = values_[Grid::index(i, i)];
    // F(α,α) = 0 by definition; tolerate rounding from a file, refuse anything else.
    if (std::fabs(d) > 1e-9 * (1.0 + scale))
      throw std::invalid_argument("table: diagonal value F(" + std::to_string(grid_.node(i)) + ", same) = " + std::to_string(d) + " must be 0");
    d = 0.0;
  }
}

InterpolationStencil EverettTable::stencil(double a, double b) const noexcept {
  InterpolationStencil st;
  double s = 0.0, t = 0.0;
  int i = 0, j = 0;
  const double lo = grid_.lo, hi = grid_.hi;
  a = a < lo ? lo : (a > hi ? hi : a);
  b = b < lo ? lo : (b > a ? a : b);
  cell_of(a, b, i, j, s, t);
  s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
  t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
  if (j == i && t > s) t = s;
  if (j < i) {
    st.node = {Grid::index(i - 1, j - 1), Grid::index(i - 1, j), Grid::index(i, j - 1), Grid::index(i, j)};
    st.weight = {(1.0 - s) * (1.0 - t), (1.0 - s) * t, s * (1.0 - t), s * t};
    st.size = 4;
  } else {
    st.node = {Grid::index(i - 1, i - 1), Grid::index(i, i - 1), Grid::index(i, i), 0};
    st.weight = {1.0 - s, s - t, t, 0.0};
    st.size = 3;
  }
  return st;
}

void EverettTable::assign_blend(const EverettTable& a, const EverettTable& b, double w) {
  if (a.values_.size() != values_.size() || b.values_.size() != values_.size())
    throw std::invalid_argument("everett table: a blend of tables with " + std::to_string(a.values_.size()) + " and " + std::to_string(b.values_.size()) +
                                " nodes into one with " + std::to_string(values_.size()));
  for (std::size_t k = 0; k < values_.size(); ++k) values_[k] = (1.0 - w) * a.values_[k] + w * b.values_[k];
  force_offset_ = (1.0 - w) * a.force_offset_ + w * b.force_offset_;
}

}  // namespace hystlab::models
