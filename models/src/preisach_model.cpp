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
  turning_.assign(options_.max_turning_points + 1, 0.0);  // + 1 spare slot
  closed_.assign(options_.max_turning_points / 2 + 2, 0.0);  // + 1 scratch slot
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
  return closed_[pairs - 1] + table_->value_in_range(turning_[len - 1], turning_[len - 2]);
}

}  // namespace hystlab::models
