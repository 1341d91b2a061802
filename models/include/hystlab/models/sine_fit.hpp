#pragma once
// Least-squares fit of y(t) = c + a cos(ωt) + b sin(ωt) at a known frequency: the amplitude and
// phase of one signal over whole cycles (transmissibility of a shaker step).
// fit_harmonics fits the fundamental and its harmonics against a phase the caller knows (the
// drive's, integrated over its commanded frequencies, so a continuous sweep is fitted as well as
// a dwell), and gives the total harmonic distortion: a hysteretic isolator's mass response is
// not a sine, and how far it is from one is a result of its own.
#include <span>

namespace hystlab::models {

struct SineFit {
  double amplitude = 0, phase_rad = 0, offset = 0, rms_residual = 0;
  bool ok = false;  // false with fewer than 4 samples or a singular design
};

[[nodiscard]] SineFit fit_sine(std::span<const double> t, std::span<const double> y, double frequency_hz) noexcept;

struct HarmonicFit {
  SineFit fundamental;  // amplitude and phase of the first harmonic (y = c + A sin(φ + phase) + ...)
  double thd = 0;       // sqrt(Σ_{k=2..H} A_k²) / A_1: 0 for a sine
  int harmonics = 0;    // H: the highest harmonic fitted
};

// y against the drive phase φ (rad) at each sample, with harmonics 1..H (1 ≤ H ≤ 9). Not ok with
// fewer than 2H + 2 samples or a singular design (a phase that covers too little of a cycle).
[[nodiscard]] HarmonicFit fit_harmonics(std::span<const double> phase_rad, std::span<const double> y, int harmonics) noexcept;

}  // namespace hystlab::models
