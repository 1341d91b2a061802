#include <algorithm>
#include <map>

#include "hystlab/models/lsq_fit.hpp"

namespace hystlab::models {
namespace {

// Adds sign * F(a, b) as stencil terms.
void add_term(const EverettTable& shape, std::map<std::size_t, double>& row, double a, double b, double sign) {
  const InterpolationStencil st = shape.stencil(a, b);
  for (int k = 0; k < st.size; ++k)
    if (st.weight[static_cast<std::size_t>(k)] != 0.0) row[st.node[static_cast<std::size_t>(k)]] += sign * st.weight[static_cast<std::size_t>(k)];
}

}  // namespace

// A plain O(depth) re-statement of Eqs. 6-7 over an explicit turning-point list: independent of
// PreisachModel's incremental bookkeeping, so the tests can check one against the other.
std::vector<std::vector<RegressorTerm>> preisach_regressors(const Grid& grid, std::span<const double> input) {
  const EverettTable shape(grid);
  std::vector<std::vector<RegressorTerm>> rows;
  rows.reserve(input.size());
  std::vector<double> tp{grid.lo};  // m0, M1, m1, ...
  double x_prev = grid.lo;
  for (double x : input) {
    x = std::clamp(x, grid.lo, grid.hi);
    if (x != x_prev) {
      const bool up = x > x_prev;
      if (up != static_cast<bool>(tp.size() & 1U)) tp.push_back(x_prev);
      if (up) {
        while (tp.size() >= 3 && x >= tp[tp.size() - 2]) tp.resize(tp.size() - 2);
      } else {
        while (tp.size() >= 2 && x <= tp[tp.size() - 2]) {
          tp.resize(tp.size() == 2 ? 1 : tp.size() - 2);
          if (tp.size() == 1) break;
        }
      }
      x_prev = x;
    }
    std::map<std::size_t, double> row;
    const std::size_t len = tp.size();
    const std::size_t closed = (len & 1U) ? len / 2 : len / 2 - 1;
    for (std::size_t k = 1; k <= closed; ++k) {
      add_term(shape, row, tp[2 * k - 1], tp[2 * k - 2], 1.0);
      add_term(shape, row, tp[2 * k - 1], tp[2 * k], -1.0);
    }
    if (len & 1U) {
      add_term(shape, row, x_prev, tp[len - 1], 1.0);
    } else {
      add_term(shape, row, tp[len - 1], tp[len - 2], 1.0);
      add_term(shape, row, tp[len - 1], x_prev, -1.0);
    }
    std::vector<RegressorTerm> terms;
    terms.reserve(row.size());
    for (const auto& [node, w] : row)
      if (w != 0.0) terms.push_back(RegressorTerm{node, w});
    rows.push_back(std::move(terms));
  }
  return rows;
}

}  // namespace hystlab::models
