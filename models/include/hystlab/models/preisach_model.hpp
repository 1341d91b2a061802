#pragma once
// The modified Preisach model evaluated through its Everett table (MODELS.md §1, Eqs. 6-7).
//
// Memory: turning points t[0] = δmin = m0, t[1] = M1, t[2] = m1, ... (wiping-out rule).
// closed_[k] keeps Σ_{i<=k} [F(M_i, m_{i-1}) - F(M_i, m_i)], so a step costs one F lookup
// whatever the history's length; wiped pairs are dropped in amortised O(1).
//
// Bounded memory: a reversal within merge_tolerance of the previous turning point is merged
// (that tiny excursion is forgotten); when max_turning_points are stored, a new reversal is
// merged the same way. Both are counted (merge_count) so the approximation is never silent.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <type_traits>
#include <vector>

#include "hystlab/models/everett_table.hpp"
#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::models {

struct PreisachOptions {
  double merge_tolerance = 0.0;          // mm; 0 keeps every reversal (the paper's model)
  std::size_t max_turning_points = 512;  // cap on the stack, >= 3; memory is preallocated
};

class PreisachModel final : public HysteresisModel {
 public:
  explicit PreisachModel(std::shared_ptr<const EverettTable> table, PreisachOptions options = {});
  explicit PreisachModel(EverettTable table, PreisachOptions options = {}) : PreisachModel(std::make_shared<const EverettTable>(std::move(table)), options) {}

  void reset() noexcept override;
  double step(double x) noexcept override { return advance(*this, x); }
  [[nodiscard]] double peek(double x) const noexcept override { return advance(*this, x); }
  [[nodiscard]] std::unique_ptr<HysteresisModel> clone() const override { return std::make_unique<PreisachModel>(*this); }
  [[nodiscard]] double input() const noexcept override { return x_; }
  [[nodiscard]] double output() const noexcept override { return f_ + table_->force_offset(); }
  [[nodiscard]] std::uint64_t saturation_count() const noexcept override { return saturations_; }
  // [kind 1, len, x, f, base, saturations, merges, invalid, turning[0..len), closed[0..len/2]].
  [[nodiscard]] std::vector<double> save_state() const override;
  void restore_state(std::span<const double> state) override;

  [[nodiscard]] std::uint64_t merge_count() const noexcept { return merges_; }
  [[nodiscard]] std::uint64_t invalid_input_count() const noexcept { return invalid_; }
  [[nodiscard]] std::size_t depth() const noexcept { return len_; }
  [[nodiscard]] const EverettTable& table() const noexcept { return *table_; }
  [[nodiscard]] const PreisachOptions& options() const noexcept { return options_; }

 private:
  // One implementation for step (Self non-const: the new state is stored) and peek (const).
  template <class Self>
  static double advance(Self& self, double x) noexcept;
  [[nodiscard]] double base_for(std::size_t len) const noexcept;

  std::shared_ptr<const EverettTable> table_;
  PreisachOptions options_;
  std::vector<double> turning_;  // capacity max_turning_points, first len_ valid
  std::vector<double> closed_;   // closed_[k]: sum over the first k closed pairs
  std::size_t len_ = 1;
  double x_ = 0.0;
  double f_ = 0.0;     // without offset
  double base_ = 0.0;  // rising: closed_[N]; falling: closed_[N-1] + F(M_N, m_{N-1})
  std::uint64_t saturations_ = 0, merges_ = 0, invalid_ = 0;
};

template <class Self>
double PreisachModel::advance(Self& self, double x) noexcept {
  constexpr bool kCommit = !std::is_const_v<Self>;
  const EverettTable& t = *self.table_;
  const double offset = t.force_offset();
  const Grid& g = t.grid();
  if (!(x >= g.lo && x <= g.hi)) [[unlikely]] {  // outside the range, or NaN
    if (std::isnan(x)) {
      if constexpr (kCommit) ++self.invalid_;
      return std::numeric_limits<double>::quiet_NaN();
    }
    if constexpr (kCommit) ++self.saturations_;
    x = x < g.lo ? g.lo : g.hi;
  }
  if (x == self.x_) return self.f_ + offset;
  const bool up = x > self.x_;
  std::size_t len = self.len_;
  const double* tp = self.turning_.data();
  double base = self.base_;
  double last = tp[len - 1];
  bool changed = false;
  // A reversal makes x_ a turning point. The usual case (append) is done without branches,
  // because for a random input it is a coin toss; merging is rare and branches.
  const bool rev = up != static_cast<bool>(len & 1U);
  // The rare condition first, so the common path has no branch on rev.
  const bool merge = rev && (len >= self.options_.max_turning_points || (len > 1 && std::fabs(self.x_ - last) <= self.options_.merge_tolerance));
  if (merge) {
    --len;  // forget the excursion since the last turning point (counted)
    changed = true;
    if constexpr (kCommit) ++self.merges_;
  } else {
    if constexpr (kCommit) {
      // Slot len is spare when there is no reversal; a new minimum (even index) closes pair
      // N = len/2, anything else writes the scratch slot at the end of closed_ (mask select).
      self.turning_[len] = self.x_;
      const std::size_t scratch = self.closed_.size() - 1, closes = (rev ? 1U : 0U) & ~len & 1U;
      self.closed_[scratch ^ ((scratch ^ (len / 2)) & (0U - closes))] = self.f_;
    }
    len += rev ? 1U : 0U;
    base = rev ? self.f_ : base;  // Eqs. 6-7: the new branch starts from the force at the reversal
    last = rev ? self.x_ : last;
  }
  // Wiping-out, one rule for both directions (no branch on the direction): the turning point
  // two below the top is of the kind the input moves toward (a maximum when rising, a minimum
  // when falling); reaching it removes it with the one after it. Falling to δmin clears all.
  const double toward = up ? 1.0 : -1.0;
  while (len >= 2 && toward * (x - tp[len - 2]) >= 0.0) {
    len = len == 2 ? 1 : len - 2;
    changed = true;
  }
  if (changed) {
    base = self.base_for(len);
    last = tp[len - 1];
  }
  // Rising from m_N: + F(x, m_N); falling from M_N: - F(M_N, x). One lookup, selected without a branch.
  const bool rising = len & 1U;
  const double v = t.value_in_range(rising ? x : last, rising ? last : x);
  const double f = base + (rising ? v : -v);
  if constexpr (kCommit) {
    self.len_ = len;
    self.base_ = base;
    self.x_ = x;
    self.f_ = f;
  }
  return f + offset;
}

}  // namespace hystlab::models
