#include "hystlab/models/preisach_model.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace hystlab::models {

PreisachModel::PreisachModel(std::shared_ptr<const EverettTable> table, PreisachOptions options)
    : table_(std::move(table)), options_(options) {
  if (!table_) throw std::invalid_argument("preisach: no table");
  if (options_.max_turning_points < 3) throw std::invalid_argument("preisach: max_turning_points must be >= 3");
  if (!(options_.merge_tolerance >= 0.0)) throw std::invalid_argument("preisach: merge_tolerance must be >= 0");
  turning_.assign(options_.max_turning_points, 0.0);
  closed_.assign(options_.max_turning_points / 2 + 1, 0.0);
  reset();
}

void PreisachModel::reset() noexcept {
  len_ = 1;
  turning_[0] = table_->grid().lo;
  closed_[0] = 0.0;
  x_ = table_->grid().lo;
  base_ = 0.0;
  f_ = 0.0;
  saturations_ = merges_ = invalid_ = 0;
}

double PreisachModel::base_for(std::size_t len) const noexcept {
  const std::size_t pairs = len / 2;
  if (len & 1U) return closed_[pairs];  // rising from m_N, N = pairs
  return closed_[pairs - 1] + table_->value(turning_[len - 1], turning_[len - 2]);
}

PreisachModel::Plan PreisachModel::plan(double x) const noexcept {
  Plan p;
  if (std::isnan(x)) {
    p.invalid = true;
    p.force = std::numeric_limits<double>::quiet_NaN();
    return p;
  }
  const Grid& g = table_->grid();
  if (x < g.lo || x > g.hi) {
    p.saturated = true;
    x = x < g.lo ? g.lo : g.hi;
  }
  p.x = x;
  if (x == x_) {
    p.force = f_ + table_->force_offset();
    return p;
  }
  p.kind = Plan::Kind::Move;
  const bool up = x > x_;
  std::size_t len = len_;
  bool changed = false;
  double base = base_;
  double last = turning_[len - 1];
  if (up != static_cast<bool>(len & 1U)) {  // direction reverses: x_ is a turning point
    const bool tiny = len > 1 && std::fabs(x_ - last) <= options_.merge_tolerance;
    if (tiny || len >= options_.max_turning_points) {
      p.merged = true;  // forget the excursion since the last turning point
      --len;
      changed = true;
    } else {
      p.append = true;  // virtual entry turning_[len] = x_; its branch base is f_ (Eqs. 6-7)
      ++len;
      base = f_;
      last = x_;
    }
  }
  if (up) {  // rising x reaching M_k wipes M_k and m_k
    while (len >= 3 && x >= turning_[len - 2]) {
      len -= 2;
      changed = true;
    }
  } else {  // falling x reaching m_{k-1} wipes it and M_k; reaching δmin clears all
    while (len >= 2 && x <= turning_[len - 2]) {
      len = (len == 2) ? 1 : len - 2;
      changed = true;
      if (len == 1) break;
    }
  }
  if (changed) {
    base = base_for(len);
    last = turning_[len - 1];
  }
  p.len = len;
  p.base = base;
  p.raw = branch_force(len, base, last, x);
  p.force = p.raw + table_->force_offset();
  return p;
}

void PreisachModel::commit(const Plan& p) noexcept {
  if (p.saturated) ++saturations_;
  if (p.merged) ++merges_;
  if (p.append) {
    turning_[len_] = x_;
    if (!(len_ & 1U)) closed_[len_ / 2] = f_;  // a new minimum closes pair N = len_/2
  }
  len_ = p.len;
  base_ = p.base;
  x_ = p.x;
  f_ = p.raw;
}

}  // namespace hystlab::models
