#include "hystlab/models/online_table_builder.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hystlab::models {
namespace {
class FotErrorCategory final : public std::error_category {
 public:
  const char* name() const noexcept override { return "hystlab.fot"; }
  std::string message(int c) const override {
    switch (static_cast<FotError>(c)) {
      case FotError::off_grid_alpha:
        return "alpha is not on a grid node";
      case FotError::off_grid_beta:
        return "beta is not on a grid node";
      case FotError::beta_above_alpha:
        return "beta is above alpha";
      case FotError::not_finite:
        return "a value is not a finite number";
    }
    return "unknown FOT error";
  }
};
}  // namespace

const std::error_category& fot_error_category() noexcept {
  static const FotErrorCategory category;
  return category;
}

OnlineTableBuilder::OnlineTableBuilder(Grid grid, double tolerance)
    : grid_(grid),
      tolerance_(tolerance >= 0.0 ? tolerance : 1e-6 * (grid.hi - grid.lo)),
      sum_(grid.node_count(), 0.0),
      count_(grid.node_count(), 0),
      f_alpha_(static_cast<std::size_t>(grid.n) + 1) {}

std::error_code OnlineTableBuilder::add(const FotNode& node) noexcept {
  if (!std::isfinite(node.alpha) || !std::isfinite(node.beta) || !std::isfinite(node.force_alpha) || !std::isfinite(node.force_alpha_beta))
    return FotError::not_finite;
  const int i = grid_.node_near(node.alpha, tolerance_);
  if (i < 0) return FotError::off_grid_alpha;
  const int j = grid_.node_near(node.beta, tolerance_);
  if (j < 0) return FotError::off_grid_beta;
  if (j > i) return FotError::beta_above_alpha;
  auto& row = f_alpha_[static_cast<std::size_t>(i)];
  // The same f_α repeated on every row of one descent is one measurement, not many.
  if (std::find(row.begin(), row.end(), node.force_alpha) == row.end()) row.push_back(node.force_alpha);
  if (j == i) return {};  // F(α,α) = 0 is enforced, whatever was measured
  const std::size_t k = Grid::index(i, j);
  sum_[k] += node.everett();
  ++count_[k];
  return {};
}

OnlineTableBuilder OnlineTableBuilder::restricted(const std::vector<int>& nodes) const {
  if (nodes.size() < 2 || nodes.front() != 0 || nodes.back() != grid_.n) throw std::invalid_argument("restricted: the nodes must run from 0 to the grid's n");
  std::vector<double> at;
  for (std::size_t a = 0; a < nodes.size(); ++a) {
    if (a > 0 && !(nodes[a] > nodes[a - 1])) throw std::invalid_argument("restricted: the nodes must increase");
    at.push_back(grid_.node(nodes[a]));
  }
  OnlineTableBuilder out(Grid::from_nodes(at), tolerance_);
  out.force_offset_ = force_offset_;
  for (std::size_t a = 0; a < nodes.size(); ++a) {
    out.f_alpha_[a] = f_alpha_[static_cast<std::size_t>(nodes[a])];
    for (std::size_t b = 0; b < a; ++b) {
      const std::size_t from = Grid::index(nodes[a], nodes[b]), to = Grid::index(static_cast<int>(a), static_cast<int>(b));
      out.sum_[to] = sum_[from];
      out.count_[to] = count_[from];
    }
  }
  return out;
}

bool OnlineTableBuilder::identified(int i, int j) const noexcept { return i == j || count_[Grid::index(i, j)] > 0; }

bool OnlineTableBuilder::cell_identified(int p, int q) const noexcept {
  if (q == p) return identified(p, p - 1);
  return identified(p - 1, q - 1) && identified(p - 1, q) && identified(p, q - 1) && identified(p, q);
}

std::size_t OnlineTableBuilder::identified_nodes() const noexcept {
  std::size_t c = 0;
  for (int i = 1; i <= grid_.n; ++i)
    for (int j = 0; j < i; ++j) c += count_[Grid::index(i, j)] > 0 ? 1U : 0U;
  return c;
}

EverettTable OnlineTableBuilder::table() const {
  std::vector<double> v(grid_.node_count(), 0.0);
  for (int i = 1; i <= grid_.n; ++i) {
    for (int j = i - 1; j >= 0; --j) {
      const std::size_t k = Grid::index(i, j);
      if (count_[k] > 0)
        v[k] = sum_[k] / count_[k];
      else if (j == i - 1)
        v[k] = 0.0;  // triangle cell with zero weight
      else           // rectangle cell (i, j+1) with zero weight
        v[k] = v[Grid::index(i, j + 1)] + v[Grid::index(i - 1, j)] - v[Grid::index(i - 1, j + 1)];
    }
  }
  return EverettTable(grid_, std::move(v), force_offset_);
}

}  // namespace hystlab::models
