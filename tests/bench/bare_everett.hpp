#pragma once
// The bare cached-Everett loop, the denominator of bench_preisach (BASELINES.md §4,
// "everett-cached"): written here from the model's definition (MODELS.md §1, Eqs. 6-9) alone, in
// the fewest lines that compute the same function as hystlab::models::PreisachModel, and none of
// its code. The memory stack m0 = δmin, M1, m1, ... with the input as its open end; the closed
// pairs' sum kept as prefix sums (the force at each new minimum is the sum through its pair), so
// a step costs one table read unless it wipes out; the table read by the paper's rectangle
// (bilinear) and diagonal-triangle interpolation, on a uniform grid by arithmetic and on a
// refined one by a binary search of the nodes. What it leaves out is what a library owes its
// users: no range check beyond clamping, no NaN, no bounded stack (its capacity is the caller's
// guess), no counters, no state to save.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace hystlab::bench {

class BareEverett {
 public:
  // nodes: δ_0..δ_n; values: F(δ_i, δ_j), j <= i, row by row (i(i+1)/2 + j).
  BareEverett(std::vector<double> nodes, std::vector<double> values, bool uniform, std::size_t capacity)
      : nodes_(std::move(nodes)), f_tab_(std::move(values)), uniform_(uniform), tp_(capacity), closed_(capacity / 2 + 2) {
    n_ = static_cast<int>(nodes_.size()) - 1, lo_ = nodes_.front(), hi_ = nodes_.back();
    inv_ = n_ / (hi_ - lo_);
    reset();
  }
  void reset() { len_ = 1, tp_[0] = lo_, closed_[0] = 0, x_ = lo_, f_ = 0, base_ = 0; }
  [[nodiscard]] std::size_t depth() const { return len_; }

  double step(double u) {
    u = u < lo_ ? lo_ : u > hi_ ? hi_ : u;
    if (u == x_) return f_;
    const bool up = u > x_, rising = len_ & 1U;
    if (up != rising) {  // a reversal: the last input is a turning point
      tp_[len_] = x_;
      if (up) closed_[len_ / 2] = f_;  // a new minimum closes its pair
      ++len_;
      base_ = f_;
    }
    bool wiped = false;
    if (up)
      while (len_ >= 3 && u >= tp_[len_ - 2]) len_ -= 2, wiped = true;
    else
      while (len_ >= 2 && u <= tp_[len_ - 2]) len_ = len_ == 2 ? 1 : len_ - 2, wiped = true;
    const double last = tp_[len_ - 1];
    if (wiped) base_ = len_ & 1U ? closed_[len_ / 2] : closed_[len_ / 2 - 1] + F(last, tp_[len_ - 2]);
    x_ = u;
    f_ = len_ & 1U ? base_ + F(u, last) : base_ - F(last, u);
    return f_;
  }

 private:
  int cell(double x, double& frac) const {
    if (uniform_) {
      const double v = (x - lo_) * inv_;
      const int i = std::min(static_cast<int>(v) + 1, n_);
      frac = v - (i - 1);
      return i;
    }
    const int i = std::clamp(static_cast<int>(std::upper_bound(nodes_.begin(), nodes_.end(), x) - nodes_.begin()), 1, n_);
    frac = (x - nodes_[static_cast<std::size_t>(i - 1)]) / (nodes_[static_cast<std::size_t>(i)] - nodes_[static_cast<std::size_t>(i - 1)]);
    return i;
  }
  double F(double a, double b) const {  // lo <= b <= a <= hi
    double s = 0, t = 0;
    const int i = cell(a, s);
    int j = cell(b, t);
    if (j > i) j = i, t = s;
    const double* r1 = f_tab_.data() + static_cast<std::size_t>((i - 1) * i / 2);
    const double* r2 = f_tab_.data() + static_cast<std::size_t>(i * (i + 1) / 2);
    if (j < i) return (1 - s) * ((1 - t) * r1[j - 1] + t * r1[j]) + s * ((1 - t) * r2[j - 1] + t * r2[j]);
    return r1[i - 1] + (r2[i - 1] - r1[i - 1]) * s + (r2[i] - r2[i - 1]) * std::min(s, t);
  }

  std::vector<double> nodes_, f_tab_;
  bool uniform_;
  int n_ = 0;
  double lo_ = 0, hi_ = 0, inv_ = 0;
  std::vector<double> tp_, closed_;
  std::size_t len_ = 1;
  double x_ = 0, f_ = 0, base_ = 0;
};

}  // namespace hystlab::bench
