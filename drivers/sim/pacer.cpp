#include "pacer.hpp"

#include <algorithm>

namespace hystlab::sim {

double Pacer::window_s() const noexcept {
  if (count_ == 0) return kMaxWindow_s;  // no rhythm yet: the first requests are not held up
  std::array<double, 8> v = intervals_;
  const std::size_t n = std::min(count_, v.size());
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n / 2), v.begin() + static_cast<std::ptrdiff_t>(n));
  return std::clamp(3.0 * v[n / 2], kMinWindow_s, kMaxWindow_s);
}

double Pacer::horizon(double now) const noexcept {
  if (!on_ || last_request_ < 0) return now;
  return std::min(now, last_request_ + window_s());
}

double Pacer::on_request(double now, double world_wall) noexcept {
  if (!on_) return world_wall;
  if (last_request_ >= 0) {
    const double skip_to = now - window_s();  // the world catches up one window, not the whole silence
    if (world_wall < skip_to) {
      lost_s_ += skip_to - world_wall;
      world_wall = skip_to;
    }
    intervals_[count_ % intervals_.size()] = now - last_request_;
    ++count_;
  }
  last_request_ = now;
  return world_wall;
}

}  // namespace hystlab::sim
