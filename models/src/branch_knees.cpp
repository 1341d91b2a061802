#include "hystlab/models/branch_knees.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace hystlab::models {
namespace {
struct Points {
  std::vector<double> x, y;
};

Points thin(std::span<const double> x, std::span<const double> y) {
  Points p;
  const std::size_t stride = std::max<std::size_t>(1, (x.size() + kMaxKneePoints - 1) / kMaxKneePoints);
  for (std::size_t k = 0; k < x.size(); k += stride) {
    p.x.push_back(x[k]);
    p.y.push_back(y[k]);
  }
  return p;
}

// f = a + b x + c (x-k1)+ + d (x-k2)+ by normal equations; returns the sum of squares.
double hinge_ss(const Points& p, double k1, double k2, Eigen::Vector4d& coef) {
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
  Eigen::Vector4d b = Eigen::Vector4d::Zero();
  for (std::size_t k = 0; k < p.x.size(); ++k) {
    const Eigen::Vector4d r(1.0, p.x[k], std::max(0.0, p.x[k] - k1), std::max(0.0, p.x[k] - k2));
    A.noalias() += r * r.transpose();
    b.noalias() += r * p.y[k];
  }
  coef = A.ldlt().solve(b);
  double ss = 0;
  for (std::size_t k = 0; k < p.x.size(); ++k) {
    const double e = coef(0) + coef(1) * p.x[k] + coef(2) * std::max(0.0, p.x[k] - k1) + coef(3) * std::max(0.0, p.x[k] - k2) - p.y[k];
    ss += e * e;
  }
  return std::isfinite(ss) ? ss : std::numeric_limits<double>::infinity();
}

double line_ss(const Points& p) {
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  for (std::size_t k = 0; k < p.x.size(); ++k) {
    const Eigen::Vector2d r(1.0, p.x[k]);
    A.noalias() += r * r.transpose();
    b.noalias() += r * p.y[k];
  }
  const Eigen::Vector2d c = A.ldlt().solve(b);
  double ss = 0;
  for (std::size_t k = 0; k < p.x.size(); ++k) ss += (c(0) + c(1) * p.x[k] - p.y[k]) * (c(0) + c(1) * p.x[k] - p.y[k]);
  return ss;
}
}  // namespace

std::optional<BranchKnees> fit_branch_knees(std::span<const double> x, std::span<const double> y) {
  if (x.size() < 10 || x.size() != y.size()) return std::nullopt;
  const Points p = thin(x, y);
  const auto [mn, mx] = std::minmax_element(p.x.begin(), p.x.end());
  const double lo = *mn, hi = *mx;
  if (!(hi > lo)) return std::nullopt;
  // Coarse grid over the range (40 steps), then three refinements of ±1 step around the best in
  // 20 sub-steps each: the knots to (hi - lo) / 40,000.
  double best = std::numeric_limits<double>::infinity(), k1 = lo, k2 = hi, step = (hi - lo) / 40;
  Eigen::Vector4d coef, c;
  for (int a = 1; a < 40; ++a)
    for (int b = a + 1; b < 40; ++b)
      if (const double ss = hinge_ss(p, lo + step * a, lo + step * b, c); ss < best) {
        best = ss;
        k1 = lo + step * a;
        k2 = lo + step * b;
        coef = c;
      }
  for (int pass = 0; pass < 3; ++pass) {
    const double c1 = k1, c2 = k2, sub = step / 10;
    for (int a = -10; a <= 10; ++a)
      for (int b = -10; b <= 10; ++b) {
        const double t1 = std::clamp(c1 + sub * a, lo, hi), t2 = std::clamp(c2 + sub * b, lo, hi);
        if (!(t2 > t1)) continue;
        if (const double ss = hinge_ss(p, t1, t2, c); ss < best) {
          best = ss;
          k1 = t1;
          k2 = t2;
          coef = c;
        }
      }
    step = sub;
  }
  if (!std::isfinite(best)) return std::nullopt;
  BranchKnees r;
  auto at = [&](double v) { return coef(0) + coef(1) * v + coef(2) * std::max(0.0, v - k1) + coef(3) * std::max(0.0, v - k2); };
  r.lower_mm = k1;
  r.lower_N = at(k1);
  r.upper_mm = k2;
  r.upper_N = at(k2);
  r.slope_start = coef(1);
  r.slope_middle = coef(1) + coef(2);
  r.slope_end = coef(1) + coef(2) + coef(3);
  const double n = static_cast<double>(p.x.size());
  r.rms_N = std::sqrt(best / n);
  r.lo_mm = lo;
  r.hi_mm = hi;
  r.line_rms_N = std::sqrt(line_ss(p) / n);
  return r;
}

}  // namespace hystlab::models
