#pragma once
// The safety envelope, independent of the plan's input: displacement, force and rate limits on
// every sample, and a watchdog on fresh samples. Pure: the runner acts on what they say.
#include <cstdint>
#include <optional>
#include <string>

#include "hystlab/domain/plan.hpp"

namespace hystlab::daemon {

class SafetyEnvelope {
 public:
  // rate_window_s: the rate is measured over at least this much rig time. Two reads can come
  // microseconds apart yet straddle one of the rig's own steps; their quotient is no velocity.
  explicit SafetyEnvelope(domain::Limits limits, double rate_window_s = 0.02) : l_(limits), window_(rate_window_s) {}
  // A reason to trip, or nothing. asked_s: rig seconds when the sample was asked for;
  // answered_s: when its answer came. A polled value was taken somewhere between the two; a
  // sample timed by the controller's own clock has them equal.
  [[nodiscard]] std::optional<std::string> check(double displacement_mm, double force_N, double asked_s, double answered_s);
  [[nodiscard]] std::optional<std::string> check(double displacement_mm, double force_N, double t_s) { return check(displacement_mm, force_N, t_s, t_s); }
  [[nodiscard]] const domain::Limits& limits() const noexcept { return l_; }

 private:
  domain::Limits l_;
  double window_, ref_x_ = 0, ref_t_ = 0;
  bool have_ref_ = false;
};

// No fresh sample (a read error, or a sample counter that did not move) for hold_after periods:
// hold; for fail_after periods: fail.
class Watchdog {
 public:
  enum class Verdict { ok, hold, fail };
  Watchdog(int hold_after, int fail_after) : hold_(hold_after), fail_(fail_after) {}
  Verdict fresh() noexcept {
    missed_ = 0;
    return Verdict::ok;
  }
  Verdict missed() noexcept {
    ++missed_;
    return missed_ >= fail_ ? Verdict::fail : missed_ >= hold_ ? Verdict::hold : Verdict::ok;
  }
  [[nodiscard]] int missed_periods() const noexcept { return missed_; }

 private:
  int hold_, fail_, missed_ = 0;
};

}  // namespace hystlab::daemon
