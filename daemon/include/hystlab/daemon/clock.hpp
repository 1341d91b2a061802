#pragma once
// The acquisition loop's clock (monotonic seconds, and sleeping until an absolute deadline), as
// an interface: the daemon uses the steady clock, the tests a fake one that jumps to each
// deadline, so supervision rules are tested fast and without sleeping.
#include <string>

namespace hystlab::daemon {

// The wall clock's UTC time to the millisecond, "2026-11-26T08:21:36.123Z": every record's stamp
// (events, runs, states). Wall time, unlike Clock below: records are read by people and across hosts.
[[nodiscard]] std::string now_iso();

class Clock {
 public:
  virtual ~Clock() = default;
  [[nodiscard]] virtual double now() = 0;
  virtual void sleep_until(double t) = 0;
};

// CLOCK_MONOTONIC, absolute deadlines (no drift across periods).
class SteadyClock final : public Clock {
 public:
  [[nodiscard]] double now() override;
  void sleep_until(double t) override;
};

// Time moves only when the loop sleeps: each sleep jumps to its deadline (plus an optional
// lateness, to play a late wake-up).
class FakeClock final : public Clock {
 public:
  explicit FakeClock(double start = 1000.0) : t_(start) {}
  [[nodiscard]] double now() override { return t_; }
  void sleep_until(double t) override {
    if (t > t_) t_ = t;
    t_ += late_;
    late_ = 0;
  }
  void advance(double dt) { t_ += dt; }
  void late_next(double dt) { late_ = dt; }

 private:
  double t_, late_ = 0;
};

}  // namespace hystlab::daemon
