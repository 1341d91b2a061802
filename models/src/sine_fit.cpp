#include "hystlab/models/sine_fit.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>

namespace hystlab::models {

SineFit fit_sine(std::span<const double> t, std::span<const double> y, double f) noexcept {
  SineFit r;
  if (t.size() != y.size() || t.size() < 4 || !(f > 0)) return r;
  const double w = 2 * std::numbers::pi * f;
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < t.size(); ++k) {
    const Eigen::Vector3d row(1.0, std::cos(w * t[k]), std::sin(w * t[k]));
    A += row * row.transpose();
    b += row * y[k];
  }
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
  if (ldlt.info() != Eigen::Success || std::fabs(A.determinant()) < 1e-12) return r;
  const Eigen::Vector3d x = ldlt.solve(b);
  r.offset = x(0);
  r.amplitude = std::hypot(x(1), x(2));
  r.phase_rad = std::atan2(x(1), x(2));  // y = c + A sin(ωt + φ)
  double ss = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    const double e = y[k] - (x(0) + x(1) * std::cos(w * t[k]) + x(2) * std::sin(w * t[k]));
    ss += e * e;
  }
  r.rms_residual = std::sqrt(ss / static_cast<double>(t.size()));
  r.ok = true;
  return r;
}

}  // namespace hystlab::models
