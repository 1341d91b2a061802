#include "hystlab/models/sma_thermal.hpp"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>

namespace hystlab::models {
namespace {
// Mean and standard error of one parameter over the isotherms.
Estimate mean_of(std::span<const SmaIsotherm> iso, double SmaIsotherm::*field) {
  double s = 0;
  for (const SmaIsotherm& i : iso) s += i.*field;
  const double n = static_cast<double>(iso.size()), m = s / n;
  double ss = 0;
  for (const SmaIsotherm& i : iso) ss += (i.*field - m) * (i.*field - m);
  return {m, std::sqrt(ss / (n - 1) / n)};
}

std::array<double, 4> forces(const SmaTransitions& t) { return {t.Ms.force, t.Mf.force, t.As.force, t.Af.force}; }
}  // namespace

SmaThermalFit fit_sma_across_temperature(std::span<const SmaIsotherm> iso) {
  std::set<double> temps;
  for (const SmaIsotherm& i : iso) {
    if (!std::isfinite(i.temperature_C)) throw std::invalid_argument("sma across temperature: an isotherm's temperature is not a finite number");
    temps.insert(i.temperature_C);
  }
  if (iso.size() < 3 || temps.size() < 3)
    throw std::invalid_argument(
        "sma across temperature: loops at three different temperatures at least are needed (the lines' uncertainty needs residuals), got " +
        std::to_string(temps.size()));
  // Unknowns [C, b_Ms, b_Mf, b_As, b_Af]; a row per isotherm and force.
  const Eigen::Index m = static_cast<Eigen::Index>(iso.size()) * 4;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(m, 5);
  Eigen::VectorXd y(m);
  for (std::size_t i = 0; i < iso.size(); ++i) {
    const std::array<double, 4> f = forces(iso[i].transitions);
    for (Eigen::Index k = 0; k < 4; ++k) {
      const Eigen::Index r = static_cast<Eigen::Index>(i) * 4 + k;
      A(r, 0) = iso[i].temperature_C;
      A(r, 1 + k) = 1.0;
      y(r) = f[static_cast<std::size_t>(k)];
    }
  }
  const Eigen::MatrixXd AtA = A.transpose() * A;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(AtA);
  const Eigen::VectorXd theta = ldlt.solve(A.transpose() * y);
  const Eigen::VectorXd r = y - A * theta;
  const double dof = static_cast<double>(m - 5), s2 = r.squaredNorm() / dof;
  const Eigen::MatrixXd cov = s2 * ldlt.solve(Eigen::MatrixXd::Identity(5, 5));
  SmaThermalFit out;
  const double C = theta(0);
  if (!(C > 0))
    throw std::invalid_argument("sma across temperature: the transformation forces do not rise with temperature (slope " + std::to_string(C) + " N/°C)");
  out.C = {C, std::sqrt(cov(0, 0))};
  // k0 = −b/C: gradient (b/C², −1/C) over (C, b).
  Estimate* zero[4] = {&out.Ms0, &out.Mf0, &out.As0, &out.Af0};
  for (Eigen::Index k = 0; k < 4; ++k) {
    const double b = theta(1 + k);
    Eigen::Vector2d g(b / (C * C), -1.0 / C);
    Eigen::Matrix2d c2;
    c2 << cov(0, 0), cov(0, 1 + k), cov(1 + k, 0), cov(1 + k, 1 + k);
    *zero[k] = {-b / C, std::sqrt(g.dot(c2 * g))};
  }
  out.KA = mean_of(iso, &SmaIsotherm::KA);
  out.KM = mean_of(iso, &SmaIsotherm::KM);
  out.dtr_max = mean_of(iso, &SmaIsotherm::dtr_max);
  out.rms_residual_N = std::sqrt(r.squaredNorm() / static_cast<double>(m));
  out.isotherms = static_cast<int>(iso.size());
  return out;
}

SmaParameters SmaThermalFit::at(double temperature_C) const noexcept {
  SmaParameters p;
  p.KA = KA.value, p.KM = KM.value, p.dtr_max = dtr_max.value, p.C = C.value;
  p.Ms0 = Ms0.value, p.Mf0 = Mf0.value, p.As0 = As0.value, p.Af0 = Af0.value;
  p.T = temperature_C;
  return p;
}

SmaIsotherm isotherm_from_loop(double temperature_C, std::span<const double> displacement, std::span<const double> force) {
  SmaCalibrationOptions o;
  o.T = temperature_C;
  const SmaCalibration c = calibrate_simplified_sma(displacement, force, o);
  return {temperature_C, c.transitions, c.parameters.KA, c.parameters.KM, c.parameters.dtr_max};
}

}  // namespace hystlab::models
