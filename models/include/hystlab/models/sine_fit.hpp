#pragma once
// Least-squares fit of y(t) = c + a cos(ωt) + b sin(ωt) at a known frequency: the amplitude and
// phase of one signal over whole cycles (transmissibility of a shaker step).
#include <span>

namespace hystlab::models {

struct SineFit {
  double amplitude = 0, phase_rad = 0, offset = 0, rms_residual = 0;
  bool ok = false;  // false with fewer than 4 samples or a singular design
};

[[nodiscard]] SineFit fit_sine(std::span<const double> t, std::span<const double> y, double frequency_hz) noexcept;

}  // namespace hystlab::models
