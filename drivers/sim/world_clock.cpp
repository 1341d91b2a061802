#include "world_clock.hpp"

#include <algorithm>

namespace hystlab::sim {

long WorldClock::steps_due(double now) noexcept {
  const double until = pacer_.horizon(now);
  double wall_dt = std::max(0.0, until - last_);
  if (wall_dt > kMaxCatchUp_s) frozen_s_ += wall_dt - kMaxCatchUp_s, wall_dt = kMaxCatchUp_s;
  last_ = std::max(last_, until);
  due_ += wall_dt * scale_;
  const auto n = static_cast<long>(due_ / dt_ + 1e-9);
  due_ = std::max(0.0, due_ - static_cast<double>(n) * dt_);
  return n;
}

}  // namespace hystlab::sim
