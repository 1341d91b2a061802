#pragma once
// Issue 42: the simplified SMA model calibrated across temperature from loops measured at
// several temperatures (docs/MODELS.md §2: the four transformation forces on lines of one slope
// in the force-temperature plane, f_k(T) = C·(T − k0) for k = Ms, Mf, As, Af).
//
// Each isothermal loop is calibrated on its own (calibrate_simplified_sma: KA, KM, δtr_max and the
// four forces); then one linear least-squares fit across the loops gives the common slope C and
// the four zero-stress temperatures k0 = −b_k/C from f_k = C·T + b_k (4m equations for m loops,
// 5 unknowns), with standard errors from the residuals (σ² = RSS/(4m − 5), covariance
// σ²(AᵀA)⁻¹, the temperatures' by the delta method). KA, KM and δtr_max do not depend on T in the
// model: their mean over the loops and its standard error.
#include <span>
#include <vector>

#include "hystlab/models/sma_calibration.hpp"

namespace hystlab::models {

struct SmaIsotherm {
  double temperature_C = 0;
  SmaTransitions transitions;  // as calibrated at that temperature
  double KA = 0, KM = 0, dtr_max = 0;
};

struct Estimate {
  double value = 0, sigma = 0;  // the estimate and its standard error
};

struct SmaThermalFit {
  Estimate C, Ms0, Mf0, As0, Af0, KA, KM, dtr_max;
  double rms_residual_N = 0;  // of the four forces about their lines
  int isotherms = 0;
  // The model at temperature T (the fitted parameters; T must be above Af0 for a superelastic
  // specimen, which SimplifiedSmaModel checks).
  [[nodiscard]] SmaParameters at(double temperature_C) const noexcept;
};

// Needs three temperatures at least (two leave the lines without residuals, so without an
// uncertainty), all different; throws std::invalid_argument naming what is missing.
[[nodiscard]] SmaThermalFit fit_sma_across_temperature(std::span<const SmaIsotherm> isotherms);

// One isothermal loop calibrated as an isotherm (calibrate_simplified_sma at that temperature).
[[nodiscard]] SmaIsotherm isotherm_from_loop(double temperature_C, std::span<const double> displacement, std::span<const double> force);

}  // namespace hystlab::models
