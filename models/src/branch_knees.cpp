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

// The moments of the points sorted by displacement, centred (u = x - mean, v = y - mean), as
// prefix sums: any hinge fit's normal equations then cost a binary search and a 4x4 solve instead
// of a pass over the points. The grid search tries about 2,000 knot pairs per branch and a
// campaign's finish measures every loop's two branches: the pass over 400 points each time was
// 82 % of an adaptive campaign's test (perf, stop 50).
class Moments {
 public:
  explicit Moments(const Points& p) : n_(p.x.size()) {
    std::vector<std::size_t> order(n_);
    for (std::size_t k = 0; k < n_; ++k) order[k] = k;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return p.x[a] < p.x[b]; });
    double sx = 0, sy = 0;
    for (std::size_t k = 0; k < n_; ++k) sx += p.x[k], sy += p.y[k];
    xm_ = sx / static_cast<double>(n_);
    ym_ = sy / static_cast<double>(n_);
    u_.resize(n_);
    for (auto* s : {&s0_, &s1_, &s2_, &sv_, &suv_}) s->assign(n_ + 1, 0.0);
    for (std::size_t k = 0; k < n_; ++k) {
      const double u = p.x[order[k]] - xm_, v = p.y[order[k]] - ym_;
      u_[k] = u;
      s0_[k + 1] = s0_[k] + 1;
      s1_[k + 1] = s1_[k] + u;
      s2_[k + 1] = s2_[k] + u * u;
      sv_[k + 1] = sv_[k] + v;
      suv_[k + 1] = suv_[k] + u * v;
      vv_ += v * v;
    }
  }

  // The sum of squares of f = a + b x + c (x-k1)+ + d (x-k2)+ fitted by least squares, k1 < k2.
  [[nodiscard]] double hinge_ss(double k1, double k2) const {
    const Tail t1 = tail(k1 - xm_), t2 = tail(k2 - xm_);
    const double c1 = k1 - xm_, c2 = k2 - xm_;
    Eigen::Matrix4d A;
    Eigen::Vector4d b;
    const double h1 = t1.s1 - c1 * t1.s0, h2 = t2.s1 - c2 * t2.s0;
    A(0, 0) = static_cast<double>(n_), A(0, 1) = s1_[n_], A(1, 1) = s2_[n_];
    A(0, 2) = h1, A(1, 2) = t1.s2 - c1 * t1.s1, A(2, 2) = t1.s2 - 2 * c1 * t1.s1 + c1 * c1 * t1.s0;
    A(0, 3) = h2, A(1, 3) = t2.s2 - c2 * t2.s1, A(3, 3) = t2.s2 - 2 * c2 * t2.s1 + c2 * c2 * t2.s0;
    A(2, 3) = t2.s2 - (c1 + c2) * t2.s1 + c1 * c2 * t2.s0;  // both hinges open only above k2
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < r; ++c) A(r, c) = A(c, r);
    b << sv_[n_], suv_[n_], t1.suv - c1 * t1.sv, t2.suv - c2 * t2.sv;
    const Eigen::Vector4d coef = A.ldlt().solve(b);
    // For any coefficients, |v - R c|^2 = v'v - 2 c'b + c'A c: exact even where A is singular.
    const double ss = vv_ - 2 * coef.dot(b) + coef.dot(A * coef);
    return std::isfinite(ss) ? std::max(0.0, ss) : std::numeric_limits<double>::infinity();
  }

 private:
  struct Tail {
    double s0, s1, s2, sv, suv;
  };
  [[nodiscard]] Tail tail(double c) const {  // the sums over the points with u > c
    const auto i = static_cast<std::size_t>(std::upper_bound(u_.begin(), u_.end(), c) - u_.begin());
    return {s0_[n_] - s0_[i], s1_[n_] - s1_[i], s2_[n_] - s2_[i], sv_[n_] - sv_[i], suv_[n_] - suv_[i]};
  }
  std::size_t n_;
  double xm_ = 0, ym_ = 0, vv_ = 0;
  std::vector<double> u_, s0_, s1_, s2_, sv_, suv_;
};

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
  for (std::size_t k = 0; k < x.size(); ++k)  // the moments sort by x: a NaN has no order
    if (!std::isfinite(x[k]) || !std::isfinite(y[k])) return std::nullopt;
  const Points p = thin(x, y);
  const auto [mn, mx] = std::minmax_element(p.x.begin(), p.x.end());
  const double lo = *mn, hi = *mx;
  if (!(hi > lo)) return std::nullopt;
  // Coarse grid over the range (40 steps), then three refinements of ±1 step around the best in
  // 20 sub-steps each: the knots to (hi - lo) / 40,000.
  double best = std::numeric_limits<double>::infinity(), k1 = lo, k2 = hi, step = (hi - lo) / 40;
  const Moments m(p);
  for (int a = 1; a < 40; ++a)
    for (int b = a + 1; b < 40; ++b)
      if (const double ss = m.hinge_ss(lo + step * a, lo + step * b); ss < best) {
        best = ss;
        k1 = lo + step * a;
        k2 = lo + step * b;
      }
  for (int pass = 0; pass < 3; ++pass) {
    const double c1 = k1, c2 = k2, sub = step / 10;
    for (int a = -10; a <= 10; ++a)
      for (int b = -10; b <= 10; ++b) {
        const double t1 = std::clamp(c1 + sub * a, lo, hi), t2 = std::clamp(c2 + sub * b, lo, hi);
        if (!(t2 > t1)) continue;
        if (const double ss = m.hinge_ss(t1, t2); ss < best) {
          best = ss;
          k1 = t1;
          k2 = t2;
        }
      }
    step = sub;
  }
  if (!std::isfinite(best)) return std::nullopt;
  Eigen::Vector4d coef;
  best = hinge_ss(p, k1, k2, coef);  // the chosen knots' fit, over the points themselves
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
