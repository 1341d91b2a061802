#pragma once
// A sine measurement window on the drive's phase (internal to the sine strategy): the phase is
// integrated over the commanded frequency as samples come, on the rig's clock; a window opens
// after some cycles of transient and closes a whole number of cycles later. Its samples are
// fitted against that phase, so a window whose frequency moved (a continuous sweep) is fitted as
// exactly as a dwell.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "hystlab/models/sine_fit.hpp"

namespace hystlab::daemon {

class SineWindow {
 public:
  SineWindow() {
    for (auto* v : {&phase_of_, &t_, &base_, &mass_}) v->reserve(1 << 16);
  }
  void restart(double t) { t_last_ = t, phase_ = 0; }
  void advance(double t, double f_hz) {
    phase_ += 2 * std::numbers::pi * f_hz * std::max(0.0, t - t_last_);
    t_last_ = t;
  }
  [[nodiscard]] double phase() const { return phase_; }
  void open(int skip_cycles, int cycles) {
    begin_ = phase_ + 2 * std::numbers::pi * skip_cycles;
    end_ = begin_ + 2 * std::numbers::pi * cycles;
    cycles_ = cycles;
    for (auto* v : {&phase_of_, &t_, &base_, &mass_}) v->clear();
  }
  void reopen() { open(0, cycles_); }
  void collect(double t, double base, double mass) {
    if (phase_ < begin_ || phase_ > end_) return;
    phase_of_.push_back(phase_), t_.push_back(t), base_.push_back(base), mass_.push_back(mass);
  }
  [[nodiscard]] bool complete() const { return phase_ >= end_; }

  // Why the window cannot be trusted, or "": fewer than 8 samples a cycle, or more than half of
  // it in gaps (a gap over a quarter cycle counts as unsampled). The fit is least squares on the
  // samples' own phases, so a hole biases nothing; what it needs is the signal's rate, not the
  // loop's. (A starved 2-core VM polled the shaker at 170 Hz with 0.6 s stalls.)
  [[nodiscard]] std::string hole() const {
    const double needed = 8.0 * cycles_, window = end_ - begin_;
    double holes = 0, longest = 0, prev = begin_;
    for (std::size_t k = 0; k <= phase_of_.size(); ++k) {
      const double p = k < phase_of_.size() ? phase_of_[k] : end_;
      const double gap = std::min(p, end_) - std::max(prev, begin_);
      longest = std::max(longest, gap);
      if (gap > 0.5 * std::numbers::pi) holes += gap;
      prev = p;
    }
    char buf[160];
    if (static_cast<double>(phase_of_.size()) < needed)
      std::snprintf(buf, sizeof buf, "%zu samples, %.0f needed", phase_of_.size(), needed);
    else if (holes > 0.5 * window)
      std::snprintf(buf, sizeof buf, "%.0f %% of its cycles in gaps (the longest %.2f cycles)", 100 * holes / window, longest / (2 * std::numbers::pi));
    else
      return {};
    return buf;
  }
  [[nodiscard]] models::HarmonicFit fit_base() const { return models::fit_harmonics(phase_of_, base_, 1); }
  [[nodiscard]] models::HarmonicFit fit_mass(int harmonics) const { return models::fit_harmonics(phase_of_, mass_, harmonics); }
  // Cycles over seconds: the window's mean frequency (a continuous sweep's point).
  [[nodiscard]] double mean_frequency() const {
    if (t_.size() < 2 || !(t_.back() > t_.front())) return 0;
    return (phase_of_.back() - phase_of_.front()) / (2 * std::numbers::pi * (t_.back() - t_.front()));
  }

 private:
  double phase_ = 0, t_last_ = 0, begin_ = 0, end_ = 0;
  int cycles_ = 1;
  std::vector<double> phase_of_, t_, base_, mass_;
};

}  // namespace hystlab::daemon
