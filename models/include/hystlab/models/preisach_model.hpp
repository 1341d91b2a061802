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
#include <cstddef>
#include <cstdint>
#include <memory>
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
  explicit PreisachModel(EverettTable table, PreisachOptions options = {})
      : PreisachModel(std::make_shared<const EverettTable>(std::move(table)), options) {}

  void reset() noexcept override;
  double step(double x) noexcept override {
    const Plan p = plan(x);
    if (p.invalid) ++invalid_;
    if (p.kind == Plan::Kind::Same) return p.force;
    commit(p);
    return p.force;
  }
  [[nodiscard]] double peek(double x) const noexcept override { return plan(x).force; }
  [[nodiscard]] std::unique_ptr<HysteresisModel> clone() const override {
    return std::make_unique<PreisachModel>(*this);
  }
  [[nodiscard]] double input() const noexcept override { return x_; }
  [[nodiscard]] double output() const noexcept override { return f_ + table_->force_offset(); }
  [[nodiscard]] std::uint64_t saturation_count() const noexcept override { return saturations_; }

  [[nodiscard]] std::uint64_t merge_count() const noexcept { return merges_; }
  [[nodiscard]] std::uint64_t invalid_input_count() const noexcept { return invalid_; }
  [[nodiscard]] std::size_t depth() const noexcept { return len_; }
  [[nodiscard]] const EverettTable& table() const noexcept { return *table_; }
  [[nodiscard]] const PreisachOptions& options() const noexcept { return options_; }

 private:
  struct Plan {
    enum class Kind { Same, Move } kind = Kind::Same;
    double x = 0.0;          // clamped input
    double force = 0.0;      // output including the table's offset
    double raw = 0.0;        // Preisach sum without offset
    std::size_t len = 0;     // stack length after the step
    double base = 0.0;       // branch base after the step
    bool append = false;     // the old input becomes a turning point at index len_ (old length)
    bool merged = false;
    bool saturated = false;
    bool invalid = false;
  };

  [[nodiscard]] Plan plan(double x) const noexcept;
  void commit(const Plan& p) noexcept;
  [[nodiscard]] double base_for(std::size_t len) const noexcept;
  [[nodiscard]] double branch_force(std::size_t len, double base, double last, double x) const noexcept {
    return (len & 1U) ? base + table_->value(x, last) : base - table_->value(last, x);
  }

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

}  // namespace hystlab::models
