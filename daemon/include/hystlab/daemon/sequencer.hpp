#pragma once
// The input a campaign drives: a list of segments (ramp to a target at a rate, then dwell),
// stepped by measured displacement and the time passed in. Pure: no I/O, no clock.
#include <cstddef>
#include <optional>
#include <vector>

#include "hystlab/domain/plan.hpp"

namespace hystlab::daemon {

enum class SegmentKind { preamble, training, rise, descent, waypoint, safe, validation };

struct Segment {
  double target_mm = 0, rate_mm_s = 0, dwell_s = 0;
  SegmentKind kind = SegmentKind::waypoint;
  int row = 0;  // FOT row i (δ_i) for rise and descent segments
};

// MODELS.md §1's identification input: (training cycles to the top), then for each repeat and
// each i = 1..n: rise to δ_i, descend to δmin. Starts with a preamble to δmin. Then, when the plan
// asks (the default), the validation input: validation_points, each a validation segment.
// Training holds training.max_cycles cycles: a rule that ends it early skips the rest.
[[nodiscard]] std::vector<Segment> fot_schedule(const domain::Plan& plan);
[[nodiscard]] std::vector<Segment> waveform_schedule(const domain::Plan& plan);
// The validation input (the paper's Fig. 18): from δmin of its range, `reversals` turning points
// drawn from the plan's seed, alternately up and down, each at least a tenth of the range away
// from the last, then back to δmin. The same plan gives the same points on every machine.
[[nodiscard]] std::vector<double> validation_points(const domain::Validation& v);

struct SetpointCommand {
  double target_mm, rate_mm_s;
};

class Sequencer {
 public:
  Sequencer(std::vector<Segment> segments, double tolerance_mm);
  // Feed the time (rig seconds) and measured displacement; returns a command when a new
  // segment starts.
  std::optional<SetpointCommand> step(double now_s, double displacement_mm);
  [[nodiscard]] bool done() const noexcept { return index_ >= segments_.size(); }
  // The current segment's target was reached: it is dwelling there (its arrival is no longer due).
  [[nodiscard]] bool in_position() const noexcept { return dwelling_; }
  [[nodiscard]] std::size_t index() const noexcept { return index_; }
  [[nodiscard]] std::size_t size() const noexcept { return segments_.size(); }
  [[nodiscard]] const Segment* current() const noexcept { return done() ? nullptr : &segments_[index_]; }
  [[nodiscard]] const Segment& at(std::size_t k) const { return segments_.at(k); }
  // The first segment of this kind from k on, or size().
  [[nodiscard]] std::size_t find(SegmentKind kind, std::size_t k = 0) const noexcept;
  // Restart at segment k (memory-aware resume re-takes the segment in progress).
  void restart_at(std::size_t k) noexcept;
  // Prepends segments before the current one (the wipe-out preamble on resume).
  void insert_before_current(const std::vector<Segment>& extra);

 private:
  std::vector<Segment> segments_;
  double tol_;
  std::size_t index_ = 0;
  bool started_ = false, dwelling_ = false;
  double dwell_until_ = 0;
};

}  // namespace hystlab::daemon
