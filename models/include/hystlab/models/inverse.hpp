#pragma once
// Inverse model for force control: the displacement whose step produces a requested force
// from the model's current memory state (bisection on peek, which leaves the state alone).
#include <system_error>

#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::models {

struct InverseResult {
  double displacement = 0.0;  // mm
  double force = 0.0;         // N actually produced at that displacement
  int iterations = 0;
  std::error_code error;  // std::errc::result_out_of_range when the force is not reachable in [lo, hi]
};

// Forces are non-decreasing in the next input for any model with non-negative Preisach weight.
[[nodiscard]] InverseResult invert(const HysteresisModel& model, double target_force, double lo, double hi, double tolerance_mm = 1e-9) noexcept;

}  // namespace hystlab::models
