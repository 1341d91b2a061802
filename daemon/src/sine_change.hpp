#pragma once
// How a stepped pass goes from one frequency to the next (internal to the sine strategy). A jump
// of the drive's frequency leaves a lightly damped isolator's mass moving as the old step had it,
// and its free vibration beats with the table's drive: the base read 81-84 % of its demand at its
// weakest through the simulated Q ≈ 25 isolator (12, 15, 17, 18.5, 22 Hz; stop 36), and a model
// of that rig (the simulator's equations, the cycle loop, 2 ms commands) put a down pass at 42 %
// (18.5 -> 17 Hz) and 65 % (17 -> 15 Hz). Two ways keep the mass on its new step's motion:
//  - Across the resonance (the mass's phase against the base on either side of -90° at the two
//    frequencies, both learnt by the loop check): the drive's phase is moved by what the mass's
//    phase against the drive moves between them, Δ = μ(f1) − μ(f2), so that at the change the
//    mass is where the new step has it. The drive cannot jump its phase (a sine controller takes a
//    frequency and an amplitude), so it is a short burst at another frequency within the plan's
//    range: the drive's phase then leads a jump's by Δ. In the model: 96 % up and 94 % down.
//  - Otherwise a glide: up to kGlideCycles cycles at frequencies in geometric steps, each driven at the
//    level learnt for it (interpolated), the cycle loop correcting as it goes and the glide
//    waiting a cycle where the base is not yet within kHoldPct, so the mass's amplitude follows
//    (the model: 94-97 % approaching or leaving the resonance; 12 cycles without waiting left
//    17 -> 15 Hz at 82 %, and the daemon read 81 % there).
// Pure bookkeeping on the drive's phase (rad, as SineWindow integrates it): no rig, no clock, no
// allocation.
#include <algorithm>
#include <cmath>
#include <numbers>

namespace hystlab::daemon {

// What the loop check learnt at a frequency (NaN: not learnt there).
struct LearntResponse {
  double ratio = NAN;                 // the mass's amplitude over the base's
  double transmissibility_rad = NAN;  // the mass's phase against the base's, in (-3π/2, π/2]
  double mass_rad = NAN;              // the mass's phase against the drive's
  [[nodiscard]] bool known() const noexcept { return std::isfinite(ratio) && std::isfinite(transmissibility_rad) && std::isfinite(mass_rad); }
};

class SineChange {
 public:
  // A glide's cycles: kGlideCyclesPerRatio for each unit the mass's motion (over the base's, as a
  // phasor) changes between the two steps, within [kMinGlideCycles, kGlideCycles]; kGlideCycles
  // where the check did not learn both. The model: 12 -> 15 Hz (1.7) at 6 cycles 96 %, 17 -> 15
  // (8.9) at 24 cycles 94 %, 22 -> 26 (1.0) at 4 cycles 99 %.
  static constexpr int kGlideCycles = 24, kMinGlideCycles = 4;
  static constexpr double kGlideCyclesPerRatio = 3;
  static constexpr double kHoldPct = 3;  // a glide's cycle further than this from the demand: not yet on
  static constexpr int kHoldFactor = 3;
  static constexpr double kBurstCycles = 0.4;                         // of the new frequency's period, when the range allows it
  static constexpr double kMinShiftRad = 5 * std::numbers::pi / 180;  // less than this: a glide

  enum class Kind { none, glide, burst };

  // From f1 to f2, starting at the drive's phase `phase`, within the plan's frequencies [lo, hi].
  void plan(double f1, double f2, double phase, const LearntResponse& p1, const LearntResponse& p2, double lo, double hi) noexcept {
    f1_ = f1, f2_ = f2, k_ = 1, cycles_ = 0;
    kind_ = Kind::none;
    if (!(f1 > 0) || !(f2 > 0) || f1 == f2) return;
    if (p1.known() && p2.known() && (p1.transmissibility_rad + kQuarter) * (p2.transmissibility_rad + kQuarter) < 0 && plan_burst(phase, p1, p2, lo, hi))
      return;
    kind_ = Kind::glide;
    n_ = kGlideCycles;
    if (p1.known() && p2.known()) {
      const double dx = p1.ratio * std::cos(p1.transmissibility_rad) - p2.ratio * std::cos(p2.transmissibility_rad);
      const double dy = p1.ratio * std::sin(p1.transmissibility_rad) - p2.ratio * std::sin(p2.transmissibility_rad);
      n_ = std::clamp(static_cast<int>(std::ceil(kGlideCyclesPerRatio * std::hypot(dx, dy))), kMinGlideCycles, kGlideCycles);
    }
    f_ = glide_frequency(1);
    end_ = phase + kTwoPi;
  }

  [[nodiscard]] bool active() const noexcept { return kind_ != Kind::none; }
  [[nodiscard]] Kind kind() const noexcept { return kind_; }
  [[nodiscard]] double frequency() const noexcept { return f_; }
  [[nodiscard]] double shift_rad() const noexcept { return shift_; }
  [[nodiscard]] int glide_cycles() const noexcept { return n_; }
  void cancel() noexcept { kind_ = Kind::none; }

  // The drive's phase now. True when the segment driven has ended: then frequency() is the next
  // one's, or the change is over (active() false) and the new step begins. (A glide whose cycles
  // the cycle loop measures moves on with them instead: next_segment.)
  bool advance(double phase) noexcept {
    if (kind_ == Kind::none || phase < end_) return false;
    next_segment(phase);
    return true;
  }
  // The next segment from the drive's phase now (each a cycle from its start, whichever way it is
  // measured: a glide that crosses 1/16 of the sample rate changes ways, review).
  void next_segment(double phase) noexcept {
    end_ = phase + kTwoPi;
    if (kind_ == Kind::glide && ++k_ < n_)
      f_ = glide_frequency(k_);
    else
      kind_ = Kind::none;
  }
  // A glide's cycle measured (cycle loop): the next frequency when its base was within
  // kHoldPct of the demand (error_pct; NaN: not measured), else the same one again, at most
  // kHoldFactor cycles a segment on average. True when the frequency moved (or the glide ended).
  bool after_cycle(double error_pct, double phase) noexcept {
    ++cycles_;
    if (std::fabs(error_pct) > kHoldPct && cycles_ < kHoldFactor * k_) return false;
    next_segment(phase);
    return true;
  }

 private:
  static constexpr double kTwoPi = 2 * std::numbers::pi, kQuarter = std::numbers::pi / 2;

  [[nodiscard]] double glide_frequency(int k) const noexcept { return f1_ * std::pow(f2_ / f1_, static_cast<double>(k) / n_); }

  // Δ wrapped to (-π, π]; the burst's frequency f2·(1 + Δ/(2π·kBurstCycles)) kept within the
  // plan's range, its length then what gives Δ: 2π·fb·t with t = Δ / (2π·(fb − f2)).
  bool plan_burst(double phase, const LearntResponse& p1, const LearntResponse& p2, double lo, double hi) noexcept {
    const double shift = std::remainder(p1.mass_rad - p2.mass_rad, kTwoPi);
    if (std::fabs(shift) < kMinShiftRad) return false;
    const double fb = std::clamp(f2_ * (1 + shift / (kTwoPi * kBurstCycles)), lo, hi);
    if (std::fabs(fb - f2_) < 1e-3 * f2_) return false;  // at the range's edge: no room to shift
    const double length = fb * shift / (fb - f2_);       // the burst's own phase
    if (!(length > 0) || length > 4 * kTwoPi) return false;
    kind_ = Kind::burst, f_ = fb, end_ = phase + length, shift_ = shift;
    return true;
  }

  Kind kind_ = Kind::none;
  double f1_ = 0, f2_ = 0, f_ = 0, end_ = 0, shift_ = 0;
  int k_ = 0, n_ = kGlideCycles, cycles_ = 0;
};

}  // namespace hystlab::daemon
