#include "hystlab/models/sma_calibration.hpp"

#include "hystlab/models/branch_knees.hpp"

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

bool residuals(const Vec7& v, const SmaCalibrationOptions& o, std::span<const double> x, std::span<const double> y, VectorXd& r) {
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

// The starting point: each branch's three tangent lines (models::fit_branch_knees, the loop
// figures' transformation points): loading gives KA, KM, Ms, Mf and so δtr_max; unloading Af, As.
Vec7 initial_guess(std::span<const double> x, std::span<const double> y) {
  const std::size_t top = static_cast<std::size_t>(std::max_element(x.begin(), x.end()) - x.begin());
  if (top + 1 < 10 || x.size() - top < 10) throw std::invalid_argument("calibrate: the loop needs at least 10 samples on loading and on unloading");
  const auto up = fit_branch_knees(x.subspan(0, top + 1), y.subspan(0, top + 1));
  const auto down = fit_branch_knees(x.subspan(top), y.subspan(top));
  if (!up || !down) throw std::invalid_argument("calibrate: the loop's branches do not span a displacement range");
  Vec7 v{};
  v[0] = up->slope_start;             // KA: first slope of loading
  v[1] = up->slope_end;               // KM: last slope of loading
  v[3] = up->lower_N;                 // fMs
  v[4] = up->upper_N;                 // fMf
  v[2] = up->upper_mm - v[4] / v[1];  // δtr_max from δMf = fMf/KM + δtr_max
  v[6] = down->lower_N;               // fAf (lower corner of unloading)
  v[5] = down->upper_N;               // fAs (upper corner)
  return v;
}

}  // namespace

SmaCalibration calibrate_simplified_sma(std::span<const double> x, std::span<const double> y, const SmaCalibrationOptions& o) {
  if (x.size() != y.size()) throw std::invalid_argument("calibrate: displacement and force differ in length");
  for (std::size_t k = 0; k < x.size(); ++k)
    if (!std::isfinite(x[k]) || !std::isfinite(y[k])) throw std::invalid_argument("calibrate: sample " + std::to_string(k) + " is not a finite number");
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
