#pragma once
// The modified Preisach model evaluated through its Everett table (MODELS.md §1, Eqs. 6-7).
//
// Memory: turning points t[0] = δmin = m0, t[1] = M1, t[2] = m1, ... (wiping-out rule).
// closed_[k] keeps Σ_{i<=k} [F(M_i, m_{i-1}) - F(M_i, m_i)], so a step costs one F lookup
// whatever the history's length; wiped pairs are dropped in amortised O(1). A step along the
// branch that stays in the input's cell costs no lookup: the cell's numbers are kept
// (BranchCell), what a smooth input's steps mostly are.
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
  bool operator==(const PreisachOptions&) const = default;
};

class PreisachModel final : public HysteresisModel {
 public:
  explicit PreisachModel(std::shared_ptr<const EverettTable> table, PreisachOptions options = {});
  explicit PreisachModel(EverettTable table, PreisachOptions options = {}) : PreisachModel(std::make_shared<const EverettTable>(std::move(table)), options) {}

  void reset() noexcept override;
  [[gnu::always_inline]] double step(double x) noexcept override { return advance(*this, x); }
  [[nodiscard]] double peek(double x) const noexcept override { return advance(*this, x); }
  [[nodiscard]] std::unique_ptr<HysteresisModel> clone() const override { return std::make_unique<PreisachModel>(*this); }
  [[nodiscard]] double input() const noexcept override { return now_.x; }
  [[nodiscard]] double output() const noexcept override { return now_.f + table_->force_offset(); }
  [[nodiscard]] std::uint64_t saturation_count() const noexcept override { return saturations_; }
  // [kind 1, len, x, f, base, saturations, merges, invalid, turning[0..len), closed[0..len/2]];
  // closed[len/2] is 0 when len is even (a scratch slot then: the same memory, the same numbers).
  [[nodiscard]] std::vector<double> save_state() const override;
  void restore_state(std::span<const double> state) override;

  // The same memory read with another table on the same nodes (the thermal model's new
  // temperature): the turning points and the input are driven again through it, O(depth), no
  // allocation; the counters are kept. Throws std::invalid_argument for a table on other nodes.
  void replace_table(std::shared_ptr<const EverettTable> table);
  // The same for a table known to be on the model's nodes (unchecked: the thermal model's tables
  // were checked once, when it was made).
  void replace_table_on_same_nodes(std::shared_ptr<const EverettTable> table) noexcept;
  // A copy of the model's own table (the same nodes and values: a copied model's own): nothing is
  // read again, so every later output is the same to the last bit.
  void use_copy_of_table(std::shared_ptr<const EverettTable> copy) noexcept { table_ = std::move(copy); }

  [[nodiscard]] std::uint64_t merge_count() const noexcept { return merges_; }
  [[nodiscard]] std::uint64_t invalid_input_count() const noexcept { return invalid_; }
  [[nodiscard]] std::size_t depth() const noexcept { return now_.len; }
  // The cell the next step along the branch may read (for tests: which kinds of cell are kept).
  [[nodiscard]] const BranchCell& kept_cell() const noexcept { return now_.cell; }
  [[nodiscard]] const EverettTable& table() const noexcept { return *table_; }
  [[nodiscard]] const PreisachOptions& options() const noexcept { return options_; }

 private:
  // One implementation for step (Self non-const: the new state is stored) and peek (const).
  // Always inlined, as what it calls, and step with it: a caller that knows the model (a loop
  // over a PreisachModel, the C API, the FMU, SdofSystem) has the step without a call in it
  // (GCC 12 at -O2 kept step out of line in SdofSystem, 108 instructions a step there, issue 27).
  template <class Self>
  [[gnu::always_inline]] static double advance(Self& self, double x) noexcept;
  // The input that wipes out the branch's next turning point, two below the top: rising (len
  // odd), a maximum, or +inf when len is 1; falling (len even), a minimum (δmin at len 2).
  [[nodiscard]] static double wipe_bound(const double* turning, std::size_t len) noexcept {
    return len >= 2 ? turning[len - 2] : std::numeric_limits<double>::infinity();
  }

  std::shared_ptr<const EverettTable> table_;
  PreisachOptions options_;
  std::vector<double> turning_;  // capacity max_turning_points + 1, first now_.len valid
  std::vector<double> closed_;   // closed_[k]: sum over the first k closed pairs
  std::vector<double> replay_;   // replace_table's copy of the turning points (same capacity)
  // The state a step moves: stepped in place, peeked in a copy (advance).
  struct Now {
    std::size_t len = 1;  // turning points stored
    double x = 0.0;
    double f = 0.0;                                          // without offset
    double base = 0.0;                                       // rising: closed_[N]; falling: closed_[N-1] + F(M_N, m_{N-1})
    double bound = std::numeric_limits<double>::infinity();  // wipe_bound of the turning points
    BranchCell cell;                                         // the input's cell on this branch (EverettTable::in_cell)
  } now_;
  std::uint64_t saturations_ = 0, merges_ = 0, invalid_ = 0;
};

// Written as the bare loop is (bench_preisach's bare_everett.hpp), on the state in place: the same
// rule kept in locals and merged at the end ran at 0.65-0.72 of it (issue 27), at par written so.
template <class Self>
inline double PreisachModel::advance(Self& self, double x) noexcept {
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
  std::conditional_t<kCommit, Now&, Now> c = self.now_;  // a step moves the state, a peek a copy of it
  if (x == c.x) return c.f + offset;
  const bool up = x > c.x;
  const double* tp = self.turning_.data();
  bool wiped = false, pushed = false;
  if (up != static_cast<bool>(c.len & 1U)) {  // a reversal: the last input is a turning point
    if (c.len >= self.options_.max_turning_points || (c.len > 1 && std::fabs(c.x - tp[c.len - 1]) <= self.options_.merge_tolerance)) [[unlikely]] {
      --c.len, wiped = true;  // forget the excursion since the last turning point (counted)
      if constexpr (kCommit) ++self.merges_;
    } else {
      if constexpr (kCommit) {
        self.turning_[c.len] = c.x;
        if (up) self.closed_[c.len / 2] = c.f;  // a new minimum closes pair N = len/2: the sum through it is f
      }
      ++c.len, pushed = true;
      c.base = c.f;  // Eqs. 6-7: the new branch starts from the force at the reversal
    }
  } else if (const double v = t.coordinate(x); (up ? x < c.bound : x > c.bound) && EverettTable::in_cell(c.cell, up, v)) [[likely]] {
    // Along the branch (nothing to wipe) in the cell of the last step: F from what it kept.
    const double e = t.cell_value(c.cell, v);
    c.x = x;
    c.f = up ? c.base + e : c.base - e;
    return c.f + offset;
  }
  // Wiping-out: the turning point two below the top is of the kind the input moves toward (a
  // maximum when rising, a minimum when falling); reaching it removes it with the one after it.
  // Falling to δmin clears all (len 1 then, odd while falling: the one place where len's parity
  // is not the direction, and why in_cell also checks the kept cell's direction).
  if (up)
    while (c.len >= 3 && x >= tp[c.len - 2]) c.len -= 2, wiped = true;
  else
    while (c.len >= 2 && x <= tp[c.len - 2]) c.len = c.len == 2 ? 1 : c.len - 2, wiped = true;
  double last = tp[c.len - 1];
  if constexpr (!kCommit) last = pushed && !wiped ? c.x : last;  // a peek stored no turning point
  if (wiped) c.base = c.len & 1U ? self.closed_[c.len / 2] : self.closed_[c.len / 2 - 1] + t.value_in_range(last, tp[c.len - 2]);
  c.x = x;
  // Rising from m_N: + F(x, m_N); falling from M_N: - F(M_N, x); x's cell kept for the next step.
  const double e = up ? t.branch_value(x, last, true, c.cell) : t.branch_value(last, x, false, c.cell);
  c.f = up ? c.base + e : c.base - e;
  c.bound = wipe_bound(tp, c.len);
  return c.f + offset;
}

}  // namespace hystlab::models
