#pragma once
// The base's amplitude over each cycle of the drive (internal to the sine strategy): what a sine
// controller's inner loop reads every cycle, where the strategy's windows (sine_window.hpp) read
// every few. A quadrature sum on the drive's phase with the cycle's mean taken out (a base that
// sits off zero leaks into a partial sum): O(1) a sample, no allocation, on the loop's thread.
#include <cmath>
#include <numbers>

namespace hystlab::daemon {

class CycleAmplitude {
 public:
  // A cycle from this phase on (after a change of drive or frequency: the cycle before mixes two).
  void restart(double phase) noexcept {
    x_ = s_ = c_ = xs_ = xc_ = 0;
    n_ = 0;
    end_ = phase + 2 * std::numbers::pi;
  }
  // A sample at the drive's phase. True when it ends a cycle: that cycle's amplitude in `a` (NaN
  // with fewer than `min_samples` in it: too few for the sum to be a sine's), and the sample opens
  // the next one.
  bool add(double phase, double x, int min_samples, double& a) noexcept {
    const bool ended = phase >= end_;
    if (ended) {
      a = n_ >= min_samples ? amplitude() : NAN;
      restart(phase >= end_ + 2 * std::numbers::pi ? phase : end_);  // a gap of a cycle or more: from here
    }
    const double sn = std::sin(phase), cs = std::cos(phase);
    x_ += x, s_ += sn, c_ += cs, xs_ += x * sn, xc_ += x * cs;
    ++n_;
    return ended;
  }

 private:
  // Σ(x − mean)·sin and ·cos over the cycle, as 2/n of their length: the fundamental's amplitude.
  [[nodiscard]] double amplitude() const noexcept {
    const double n = static_cast<double>(n_), mean = x_ / n;
    return 2 * std::hypot(xs_ - mean * s_, xc_ - mean * c_) / n;
  }
  double x_ = 0, s_ = 0, c_ = 0, xs_ = 0, xc_ = 0, end_ = 0;
  int n_ = 0;
};

}  // namespace hystlab::daemon
