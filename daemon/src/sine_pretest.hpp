#pragma once
// The loop check before a stepped sweep's first pass, as sine controllers run one before a test
// level: every planned frequency, ascending, at control.pretest_level × the plan's smallest
// amplitude (-12 dB), held until the table's response there (base per unit of drive, which the
// base control learns from every window) agrees between two windows in a row within 2 %, at most
// 8 windows. Every step of the sweep then starts at the drive its own frequency asks for. Without
// it a step across the isolator's resonance starts at the drive learnt on the other side: the
// simulated table's response changes 2.5 times between 17 and 18.5 Hz (the mass's reaction on
// the table), and the base read 22 % of its demand for a window there. Pure bookkeeping (no rig,
// no clock); fixed storage, filled before the campaign starts.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "hystlab/domain/events.hpp"
#include "hystlab/domain/sine_plan.hpp"
#include "sine_change.hpp"

namespace hystlab::daemon {

class SinePretest {
 public:
  static constexpr double kAgree = 0.02;  // two windows' responses this close: settled
  static constexpr int kMaxWindows = 8;   // a frequency's windows at most

  explicit SinePretest(const domain::SinePlan& s) : freqs_(domain::pretest_frequencies(s)), phases_(freqs_.size()) {
    double smallest = INFINITY;
    for (const double a : s.amplitudes_mm) smallest = std::min(smallest, a);
    level_ = s.control.pretest_level * smallest;
  }

  [[nodiscard]] bool active() const noexcept { return k_ < freqs_.size(); }
  [[nodiscard]] double frequency() const noexcept { return freqs_[k_]; }
  [[nodiscard]] double level() const noexcept { return level_; }
  [[nodiscard]] std::size_t frequencies() const noexcept { return freqs_.size(); }

  // The frequency (again, after a pause or a held link): its windows counted afresh.
  void restart_frequency() noexcept { windows_here_ = 0, prev_ = NAN; }

  // A window's response at the current frequency, with the phases the step changes plan from
  // (the last window's are kept). True when the frequency is done: two in a row agree (a ringing
  // isolator's do not: its windows go on), or it is out of windows.
  bool window(double response, const LearntResponse& phases) noexcept {
    phases_[k_] = phases;
    ++windows_, ++windows_here_;
    const bool agree = windows_here_ > 1 && std::fabs(response / prev_ - 1) <= kAgree;
    prev_ = response;
    if (!agree && windows_here_ < kMaxWindows) return false;
    if (!agree) ++unsettled_;
    lo_ = std::min(lo_, response), hi_ = std::max(hi_, response);
    ++k_;
    restart_frequency();
    return true;
  }

  // What was learnt at f (a planned frequency; NaN elsewhere): freqs_ ascending.
  [[nodiscard]] LearntResponse phases_at(double f) const noexcept {
    const auto it = std::lower_bound(freqs_.begin(), freqs_.end(), f * (1 - 1e-9));
    if (it == freqs_.end() || std::fabs(*it - f) > 1e-9 * f) return {};
    return phases_[static_cast<std::size_t>(it - freqs_.begin())];
  }

  [[nodiscard]] domain::PretestEvent summary(double seconds) const {
    domain::PretestEvent e;
    e.frequencies = static_cast<std::int64_t>(freqs_.size()), e.windows = windows_, e.unsettled = unsettled_;
    e.level_mm = level_, e.seconds = seconds, e.response_min = lo_, e.response_max = hi_;
    return e;
  }

 private:
  std::vector<double> freqs_;
  std::vector<LearntResponse> phases_;  // at each of freqs_
  std::size_t k_ = 0;
  double level_ = 0, prev_ = NAN, lo_ = INFINITY, hi_ = -INFINITY;
  std::int64_t windows_ = 0, unsettled_ = 0;
  int windows_here_ = 0;
};

}  // namespace hystlab::daemon
