#pragma once
// A resonance dwell's frequency (internal to the sine strategy): moved window by window until
// the mass's phase against the base is the target, by Newton's step in log frequency on the
// phase's slope dφ/d(ln f). The slope is learnt by secant from the windows measured (a linear
// isolator's is −2Q at its natural frequency: −50 at Q = 25, where it starts); each step is at
// most 2 % of the frequency and `gain` of Newton's (the phase of a window just after a change
// still carries some of the change's transient), and stays within [lo, hi].
#include <algorithm>
#include <cmath>
#include <numbers>

namespace hystlab::daemon {

class PhaseTracker {
 public:
  void start(double target_rad, double lo_hz, double hi_hz) noexcept { target_ = target_rad, lo_ = lo_hz, hi_ = hi_hz, slope_ = -50, have_prev_ = false; }
  // Phase minus target, wrapped to (−π, π].
  [[nodiscard]] double error(double phase_rad) const noexcept { return std::remainder(phase_rad - target_, 2 * std::numbers::pi); }
  // The frequency for the next window, after one measured at f with this phase.
  [[nodiscard]] double next(double f, double phase_rad) noexcept {
    const double x = std::log(f);
    if (have_prev_ && std::fabs(x - prev_x_) > 1e-3) {
      // A slope of the wrong sign or beyond any isolator's (Q of 0.5 to 1000) is noise: kept out.
      const double s = std::remainder(phase_rad - prev_phase_, 2 * std::numbers::pi) / (x - prev_x_);
      if (s < -1 && s > -2000) slope_ = 0.5 * slope_ + 0.5 * s;
    }
    have_prev_ = true, prev_x_ = x, prev_phase_ = phase_rad;
    const double dx = std::clamp(-kGain * error(phase_rad) / slope_, -kMaxStep, kMaxStep);
    return std::clamp(f * std::exp(dx), lo_, hi_);
  }
  [[nodiscard]] double slope() const noexcept { return slope_; }

 private:
  static constexpr double kGain = 0.7, kMaxStep = 0.02;
  double target_ = 0, lo_ = 0, hi_ = 0, slope_ = -50, prev_x_ = 0, prev_phase_ = 0;
  bool have_prev_ = false;
};

}  // namespace hystlab::daemon
