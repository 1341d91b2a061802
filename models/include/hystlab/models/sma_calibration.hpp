#pragma once
// Calibration of the simplified SMA model from one measured loop (nonlinear least squares).
//
// One isothermal loop determines seven numbers: KA, KM, δtr_max and the four transition forces.
// C and T cannot be separated from the transition temperatures at one temperature, so they are
// given, and Mf0 = T - fMf/C (likewise Ms0, As0, Af0) are derived from the fitted forces.
#include <span>

#include "hystlab/models/simplified_sma.hpp"

namespace hystlab::models {

struct SmaCalibrationOptions {
  double C = 5.7;   // N/°C, Clausius-Clapeyron slope (given)
  double T = 25.0;  // °C, test temperature (given)
  int max_iterations = 200;
};

struct SmaCalibration {
  SmaParameters parameters;
  SmaTransitions transitions;   // fitted transition points
  SmaParameters initial_guess;  // from piecewise-linear fits of each branch
  double rms_residual = 0.0;    // N
  double max_residual = 0.0;    // N
  int iterations = 0;
};

// The loop must load past the end of the forward transformation and unload below the end of
// the reverse one; throws std::invalid_argument when the data cannot determine the parameters.
[[nodiscard]] SmaCalibration calibrate_simplified_sma(std::span<const double> displacement, std::span<const double> force,
                                                      const SmaCalibrationOptions& options = {});

}  // namespace hystlab::models
