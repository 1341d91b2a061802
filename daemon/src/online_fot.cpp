#include "hystlab/daemon/online_fot.hpp"

#include <cmath>

namespace hystlab::daemon {

OnlineFot::OnlineFot(models::Grid grid, double dead_band_mm, NodeSink sink) : grid_(grid), band_(dead_band_mm), sink_(std::move(sink)) {}

bool OnlineFot::take_descent_completed() noexcept {
  const bool f = descent_flag_;
  descent_flag_ = false;
  return f;
}

void OnlineFot::top_reached(double, double x, double f, bool collect) {
  row_ = -1;
  if (!collect) return;
  const int i = grid_.node_near(x, 0.25 * grid_.step());
  if (i < 1) return;  // not a FOT top (a wiggle, or the bottom of the range)
  row_ = i;
  next_j_ = i - 1;
  f_alpha_ = f;
}

void OnlineFot::bottom_reached(double t, double f) {
  if (row_ >= 1 && next_j_ == 0 && std::fabs(ext_x_ - grid_.lo) <= 0.25 * grid_.step()) sink_(models::FotNode{grid_.node(row_), grid_.lo, f_alpha_, f}, t);
  if (row_ >= 1) {
    ++descents_;
    descent_flag_ = true;
  }
  row_ = -1;
}

void OnlineFot::feed(double t, double x, double f, bool collect) {
  // Nodes inside an open descent: each δ_j (j >= 1) passed on the way down.
  if (row_ >= 1 && dir_ < 0 && have_prev_) {
    // Two samples further apart than half a cell, and late (over 3 expected spacings), are a
    // hole (a lost link, a stalled host), not a measurement: a node inside it is not guessed by
    // interpolation; it stays missing, and the row is taken again. Coarse but regular sampling
    // is no hole.
    const bool hole = spacing_s_ > 0 && prev_x_ - x > 0.5 * grid_.step() && t - prev_t_ > 3 * spacing_s_;
    while (next_j_ >= 1 && x <= grid_.node(next_j_) && prev_x_ > grid_.node(next_j_)) {
      const double level = grid_.node(next_j_);
      const double s = (prev_x_ - level) / (prev_x_ - x);
      if (!hole) sink_(models::FotNode{grid_.node(row_), level, f_alpha_, prev_f_ + s * (f - prev_f_)}, t);
      --next_j_;
    }
  }
  if (dir_ == 0) {
    if (!have_prev_) ext_x_ = x, ext_f_ = f, ext_t_ = t;
    if (std::fabs(x - ext_x_) > band_) dir_ = x > ext_x_ ? 1 : -1;
  } else if ((dir_ > 0 && x >= ext_x_) || (dir_ < 0 && x <= ext_x_)) {
    ext_x_ = x, ext_f_ = f, ext_t_ = t;        // still going the same way: a new extreme
  } else if (std::fabs(x - ext_x_) > band_) {  // a reversal at the last extreme
    if (dir_ > 0)
      top_reached(ext_t_, ext_x_, ext_f_, collect);
    else
      bottom_reached(ext_t_, ext_f_);
    dir_ = -dir_;
    ext_x_ = x, ext_f_ = f, ext_t_ = t;  // (the dead band is far smaller than a cell: no δ_j was passed yet)
  }
  prev_x_ = x, prev_f_ = f, prev_t_ = t;
  have_prev_ = true;
}

void OnlineFot::finish() {
  if (dir_ < 0) bottom_reached(ext_t_, ext_f_);
}

}  // namespace hystlab::daemon
