#include "hystlab/models/sma_calibration.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace hystlab::models {
namespace {
using Eigen::MatrixXd;
using Eigen::VectorXd;
using Vec7 = std::array<double, 7>;  // KA, KM, dtr_max, fMs, fMf, fAs, fAf

SmaParameters to_parameters(const Vec7& v, const SmaCalibrationOptions& o) {
  SmaParameters p;
  p.KA = v[0];
  p.KM = v[1];
  p.dtr_max = v[2];
  p.C = o.C;
  p.T = o.T;
  p.Ms0 = o.T - v[3] / o.C;
  p.Mf0 = o.T - v[4] / o.C;
  p.As0 = o.T - v[5] / o.C;
  p.Af0 = o.T - v[6] / o.C;
  return p;
}

bool residuals(const Vec7& v, const SmaCalibrationOptions& o, std::span<const double> x, std::span<const double> y,
               VectorXd& r) {
  const SmaParameters p = to_parameters(v, o);
  try {
    validate(p);
  } catch (const std::invalid_argument&) {
    return false;
  }
  SimplifiedSmaModel model(p);
  r.resize(static_cast<Eigen::Index>(x.size()));
  for (std::size_t k = 0; k < x.size(); ++k) r(static_cast<Eigen::Index>(k)) = model.step(x[k]) - y[k];
  return true;
}

// Continuous three-segment line through a branch: f = a + b x + c (x-k1)+ + d (x-k2)+, best (k1, k2).
struct Hinge {
  double k1 = 0, k2 = 0;
  Eigen::Vector4d coef = Eigen::Vector4d::Zero();
  double at(double x) const {
    return coef(0) + coef(1) * x + coef(2) * std::max(0.0, x - k1) + coef(3) * std::max(0.0, x - k2);
  }
};

Hinge fit_hinge(const std::vector<double>& x, const std::vector<double>& y) {
  const auto [mn, mx] = std::minmax_element(x.begin(), x.end());
  const double lo = *mn, hi = *mx;
  Hinge best;
  double best_ss = std::numeric_limits<double>::infinity();
  const int steps = 40;
  MatrixXd A(static_cast<Eigen::Index>(x.size()), 4);
  VectorXd Y = Eigen::Map<const VectorXd>(y.data(), static_cast<Eigen::Index>(y.size()));
  for (int a = 1; a < steps; ++a)
    for (int b = a + 1; b < steps; ++b) {
      const double k1 = lo + (hi - lo) * a / steps, k2 = lo + (hi - lo) * b / steps;
      for (std::size_t k = 0; k < x.size(); ++k) {
        const auto r = static_cast<Eigen::Index>(k);
        A(r, 0) = 1.0;
        A(r, 1) = x[k];
        A(r, 2) = std::max(0.0, x[k] - k1);
        A(r, 3) = std::max(0.0, x[k] - k2);
      }
      const Eigen::Vector4d c = (A.transpose() * A).ldlt().solve(A.transpose() * Y);
      const double ss = (A * c - Y).squaredNorm();
      if (ss < best_ss) {
        best_ss = ss;
        best = Hinge{k1, k2, c};
      }
    }
  return best;
}

Vec7 initial_guess(std::span<const double> x, std::span<const double> y) {
  const std::size_t top = static_cast<std::size_t>(std::max_element(x.begin(), x.end()) - x.begin());
  std::vector<double> ux, uy, dx, dy;
  for (std::size_t k = 0; k < x.size(); ++k) {
    auto& bx = k <= top ? ux : dx;
    auto& by = k <= top ? uy : dy;
    bx.push_back(x[k]);
    by.push_back(y[k]);
  }
  if (ux.size() < 10 || dx.size() < 10)
    throw std::invalid_argument("calibrate: the loop needs at least 10 samples on loading and on unloading");
  const Hinge up = fit_hinge(ux, uy), down = fit_hinge(dx, dy);
  Vec7 v{};
  v[0] = up.coef(1);                                         // KA: first slope of loading
  v[1] = up.coef(1) + up.coef(2) + up.coef(3);               // KM: last slope of loading
  v[3] = up.at(up.k1);                                       // fMs
  v[4] = up.at(up.k2);                                       // fMf
  v[2] = up.k2 - v[4] / v[1];                                // δtr_max from δMf = fMf/KM + δtr_max
  v[6] = down.at(down.k1);                                   // fAf (lower corner of unloading)
  v[5] = down.at(down.k2);                                   // fAs (upper corner)
  return v;
}

}  // namespace

SmaCalibration calibrate_simplified_sma(std::span<const double> x, std::span<const double> y,
                                        const SmaCalibrationOptions& o) {
  if (x.size() != y.size()) throw std::invalid_argument("calibrate: displacement and force differ in length");
  for (std::size_t k = 0; k < x.size(); ++k)
    if (!std::isfinite(x[k]) || !std::isfinite(y[k]))
      throw std::invalid_argument("calibrate: sample " + std::to_string(k) + " is not a finite number");
  if (!(o.C > 0) || !std::isfinite(o.T)) throw std::invalid_argument("calibrate: C must be > 0 and T finite");
  Vec7 v = initial_guess(x, y);
  SmaCalibration out;
  out.initial_guess = to_parameters(v, o);
  VectorXd r, r_try;
  if (!residuals(v, o, x, y, r))
    throw std::invalid_argument(
        "calibrate: the loop does not show both transformations (load past the end of the forward "
        "transformation and unload below the end of the reverse one)");
  double cost = r.squaredNorm(), mu = 1e-3;
  const Eigen::Index n = static_cast<Eigen::Index>(x.size());
  MatrixXd J(n, 7);
  for (out.iterations = 0; out.iterations < o.max_iterations; ++out.iterations) {
    for (int j = 0; j < 7; ++j) {  // forward differences: the model is piecewise linear in x, not in v
      Vec7 vp = v;
      const double h = 1e-6 * std::max(1.0, std::fabs(v[static_cast<std::size_t>(j)]));
      vp[static_cast<std::size_t>(j)] += h;
      if (!residuals(vp, o, x, y, r_try)) {
        vp[static_cast<std::size_t>(j)] -= 2 * h;
        residuals(vp, o, x, y, r_try);
        J.col(j) = (r - r_try) / h;
      } else {
        J.col(j) = (r_try - r) / h;
      }
    }
    const MatrixXd JtJ = J.transpose() * J;
    const VectorXd Jtr = J.transpose() * r;
    bool improved = false;
    for (int attempt = 0; attempt < 20 && !improved; ++attempt) {
      MatrixXd Aug = JtJ;
      Aug.diagonal() += mu * JtJ.diagonal().cwiseMax(1e-12);
      const VectorXd step = Aug.ldlt().solve(-Jtr);
      Vec7 vt = v;
      for (int j = 0; j < 7; ++j) vt[static_cast<std::size_t>(j)] += step(j);
      if (residuals(vt, o, x, y, r_try) && r_try.squaredNorm() < cost) {
        const double gain = cost - r_try.squaredNorm();
        v = vt;
        r = r_try;
        cost = r.squaredNorm();
        mu = std::max(mu / 3.0, 1e-12);
        improved = true;
        if (gain < 1e-12 * cost) out.iterations = o.max_iterations;  // converged
      } else {
        mu *= 4.0;
      }
    }
    if (!improved) break;
  }
  out.parameters = to_parameters(v, o);
  out.transitions = transitions(out.parameters);
  out.rms_residual = std::sqrt(cost / static_cast<double>(n));
  out.max_residual = r.cwiseAbs().maxCoeff();
  return out;
}

}  // namespace hystlab::models
