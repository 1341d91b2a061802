#pragma once
// Online FOT identification from measured samples (issue: "fit the Preisach table online").
// Reversals of the measured displacement are found with a dead band, so noise makes none. A top
// near grid node δ_i opens row i: f_α is the force at the top, and as the descent passes each
// δ_j the force there (interpolated between the two samples around the crossing) gives node
// F(δ_i, δ_j). The bottom of the descent (the next reversal, or finish()) gives δ_j = δmin.
#include <functional>
#include <vector>

#include "hystlab/models/fot_node.hpp"
#include "hystlab/models/grid.hpp"

namespace hystlab::daemon {

class OnlineFot {
 public:
  using NodeSink = std::function<void(const models::FotNode&, double t)>;
  OnlineFot(models::Grid grid, double dead_band_mm, NodeSink sink);
  // collect = false outside the identification input (training cycles, preambles).
  void feed(double t, double x, double f, bool collect);
  // The expected time between samples: with it, a node inside a hole in the data (samples over
  // half a cell and 3 spacings apart) is left missing instead of interpolated. 0 (the default,
  // offline data): every crossing is interpolated.
  void set_spacing(double seconds) noexcept { spacing_s_ = seconds; }
  // Ends a descent still open at the end of the input (its bottom gives the δmin node).
  void finish();
  [[nodiscard]] int descents_completed() const noexcept { return descents_; }
  // A descent of row i passed its last δ_j and waits for its bottom (the next reversal, or
  // finish()) to give node (i, 0).
  [[nodiscard]] bool bottom_pending(int i) const noexcept { return row_ == i && next_j_ == 0; }
  // True once after each completed descent (then cleared): the moment to re-evaluate the table.
  bool take_descent_completed() noexcept;

 private:
  void top_reached(double t, double x, double f, bool collect);
  void bottom_reached(double t, double f);

  models::Grid grid_;
  double band_;
  NodeSink sink_;
  int dir_ = 0;  // +1 rising, -1 falling, 0 unknown
  double ext_x_ = 0, ext_f_ = 0, ext_t_ = 0;
  double prev_x_ = 0, prev_f_ = 0, prev_t_ = 0, spacing_s_ = 0;
  bool have_prev_ = false;
  int row_ = -1, next_j_ = -1;  // open descent: row i and the next δ_j to pass
  double f_alpha_ = 0;
  int descents_ = 0;
  bool descent_flag_ = false;
};

}  // namespace hystlab::daemon
