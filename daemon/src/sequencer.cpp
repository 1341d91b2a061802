#include "hystlab/daemon/sequencer.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace hystlab::daemon {

std::vector<Segment> fot_schedule(const domain::Plan& p) {
  std::vector<Segment> s;
  s.push_back({p.lo_mm, p.ramp_rate_mm_s, p.dwell_s, SegmentKind::preamble, 0});
  for (int c = 0; c < p.training.max_cycles; ++c) {  // stabilise the specimen on its major loop
    s.push_back({p.hi_mm, p.ramp_rate_mm_s, 0.0, SegmentKind::training, 0});
    s.push_back({p.lo_mm, p.ramp_rate_mm_s, p.dwell_s, SegmentKind::training, 0});
  }
  const models::Grid g = domain::fot_grid(p);
  // A row is numbered by its top's node on the grid its nodes are measured on (an adaptive
  // design's finest grid: the coarse grid's node i is node i·stride there).
  const int stride = p.design.adaptive ? p.design.finest_subdivisions / p.subdivisions : 1;
  for (int r = 0; r < p.repeats; ++r)
    for (int i = 1; i <= p.subdivisions; ++i) {
      const double top = g.node(i);
      s.push_back({top, p.ramp_rate_mm_s, p.dwell_s, SegmentKind::rise, i * stride});
      s.push_back({p.lo_mm, p.ramp_rate_mm_s, p.dwell_s, SegmentKind::descent, i * stride});
    }
  if (p.validation.enabled)
    for (const double x : validation_points(p.validation)) s.push_back({x, p.validation.rate_mm_s, 0.0, SegmentKind::validation, 0});
  return s;
}

std::vector<double> validation_points(const domain::Validation& v) {
  std::mt19937_64 rng(v.seed);
  // From the generator's bits, not std::uniform_real_distribution (whose mapping the standard
  // leaves to the library): the same plan gives the same input everywhere.
  auto uniform = [&rng](double a, double b) { return a + (b - a) * static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  const double span = v.hi_mm - v.lo_mm, gap = 0.1 * span;
  std::vector<double> out{v.lo_mm};
  double x = v.lo_mm;
  for (int r = 0; r < v.reversals; ++r) {
    const bool up = r % 2 == 0;
    x = up ? uniform(std::min(x + gap, v.hi_mm), v.hi_mm) : uniform(v.lo_mm, std::max(x - gap, v.lo_mm));
    out.push_back(x);
  }
  out.push_back(v.lo_mm);
  return out;
}

std::vector<Segment> waveform_schedule(const domain::Plan& p) {
  std::vector<Segment> s;
  for (double x : p.points_mm) s.push_back({x, p.ramp_rate_mm_s, p.dwell_s, SegmentKind::waypoint, 0});
  return s;
}

Sequencer::Sequencer(std::vector<Segment> segments, double tolerance_mm) : segments_(std::move(segments)), tol_(tolerance_mm) {}

std::optional<SetpointCommand> Sequencer::step(double now, double x) {
  if (done()) return std::nullopt;
  const Segment& seg = segments_[index_];
  if (!started_) {
    started_ = true;
    dwelling_ = false;
    return SetpointCommand{seg.target_mm, seg.rate_mm_s};
  }
  if (!dwelling_ && std::fabs(x - seg.target_mm) <= tol_) {
    dwelling_ = true;
    dwell_until_ = now + seg.dwell_s;
  }
  if (dwelling_ && now >= dwell_until_) {
    ++index_;
    started_ = false;
    return step(now, x);
  }
  return std::nullopt;
}

std::size_t Sequencer::find(SegmentKind kind, std::size_t k) const noexcept {
  while (k < segments_.size() && segments_[k].kind != kind) ++k;
  return k;
}

void Sequencer::restart_at(std::size_t k) noexcept {
  index_ = k;
  started_ = dwelling_ = false;
}

void Sequencer::insert_before_current(const std::vector<Segment>& extra) {
  segments_.insert(segments_.begin() + static_cast<std::ptrdiff_t>(index_), extra.begin(), extra.end());
  started_ = dwelling_ = false;
}

}  // namespace hystlab::daemon
