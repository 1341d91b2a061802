#include "hystlab/models/sine_fit.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <vector>

namespace hystlab::models {

SineFit fit_sine(std::span<const double> t, std::span<const double> y, double f) noexcept {
  if (t.size() != y.size() || t.size() < 4 || !(f > 0)) return {};
  const double w = 2 * std::numbers::pi * f;
  std::vector<double> phase(t.size());
  for (std::size_t k = 0; k < t.size(); ++k) phase[k] = w * t[k];
  return fit_harmonics(phase, y, 1).fundamental;
}

HarmonicFit fit_harmonics(std::span<const double> phase, std::span<const double> y, int harmonics) noexcept {
  HarmonicFit r;
  const int h = harmonics, m = 2 * harmonics + 1;
  if (h < 1 || h > 9 || phase.size() != y.size() || phase.size() < static_cast<std::size_t>(m + 1)) return r;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(m, m);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(m), row(m);
  auto fill = [&](double p) {
    row(0) = 1.0;
    for (int k = 1; k <= h; ++k) row(2 * k - 1) = std::cos(k * p), row(2 * k) = std::sin(k * p);
  };
  for (std::size_t i = 0; i < phase.size(); ++i) {
    fill(phase[i]);
    A.selfadjointView<Eigen::Lower>().rankUpdate(row);
    b += row * y[i];
  }
  A = A.selfadjointView<Eigen::Lower>();
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
  // A design that does not span a cycle is near-singular: its smallest pivot is far below the
  // largest (a whole number of cycles gives n/2 on every harmonic, n on the offset).
  const auto d = ldlt.vectorD().cwiseAbs();
  if (ldlt.info() != Eigen::Success || !(d.minCoeff() > 1e-9 * d.maxCoeff())) return r;
  const Eigen::VectorXd x = ldlt.solve(b);
  double ss = 0;
  for (std::size_t i = 0; i < phase.size(); ++i) {
    fill(phase[i]);
    const double e = y[i] - row.dot(x);
    ss += e * e;
  }
  SineFit& f = r.fundamental;
  f.offset = x(0);
  f.amplitude = std::hypot(x(1), x(2));
  f.phase_rad = std::atan2(x(1), x(2));  // y = c + A sin(φ + phase)
  f.rms_residual = std::sqrt(ss / static_cast<double>(phase.size()));
  f.ok = true;
  double higher = 0;
  for (int k = 2; k <= h; ++k) higher += x(2 * k - 1) * x(2 * k - 1) + x(2 * k) * x(2 * k);
  r.thd = f.amplitude > 0 ? std::sqrt(higher) / f.amplitude : 0.0;
  r.harmonics = h;
  return r;
}

}  // namespace hystlab::models
