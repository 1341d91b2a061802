#include "hystlab/models/lsq_fit.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "fit_record.hpp"
#include "hystlab/models/preisach_model.hpp"

namespace hystlab::models {
namespace {
using Eigen::MatrixXd;
using Eigen::VectorXd;
using Index = Eigen::Index;

Index idx(std::size_t k) { return static_cast<Index>(k); }

// Node values from cell masses: F(δ_i, δ_j) = Σ_{p <= i, q >= j+1} w_pq. The last column is the offset.
MatrixXd cumulative_map(const Grid& g) {
  const std::size_t nodes = g.node_count(), cells = g.cell_count();
  MatrixXd P = MatrixXd::Zero(idx(nodes) + 1, idx(cells) + 1);
  for (int i = 1; i <= g.n; ++i)
    for (int j = 0; j < i; ++j)
      for (int p = j + 1; p <= i; ++p)
        for (int q = j + 1; q <= p; ++q) P(idx(Grid::index(i, j)), idx(Grid::cell_index(p, q))) = 1.0;
  P(idx(nodes), idx(cells)) = 1.0;
  return P;
}

// First differences between neighbouring cells; the offset is not smoothed.
MatrixXd smoothing(const Grid& g) {
  const std::size_t cells = g.cell_count();
  MatrixXd L = MatrixXd::Zero(idx(cells) + 1, idx(cells) + 1);
  auto couple = [&](std::size_t a, std::size_t b) {
    L(idx(a), idx(a)) += 1;
    L(idx(b), idx(b)) += 1;
    L(idx(a), idx(b)) -= 1;
    L(idx(b), idx(a)) -= 1;
  };
  for (int p = 1; p <= g.n; ++p)
    for (int q = 1; q <= p; ++q) {
      if (p < g.n) couple(Grid::cell_index(p, q), Grid::cell_index(p + 1, q));
      if (q < p) couple(Grid::cell_index(p, q), Grid::cell_index(p, q + 1));
    }
  return L;
}

struct ActiveSetResult {
  VectorXd w;
  std::vector<bool> passive;
  int iterations = 0;
};

// min ½wᵀQw - gᵀw subject to w_c >= 0 for every cell (all but the last, free, variable).
// Lawson-Hanson on the normal equations, warm-started from the clipped unconstrained solution.
ActiveSetResult solve_nonnegative(const MatrixXd& Q, const VectorXd& g, const VectorXd& start) {
  const Index m = Q.rows(), free_var = m - 1;
  ActiveSetResult r{VectorXd::Zero(m), std::vector<bool>(static_cast<std::size_t>(m), false), 0};
  r.passive[static_cast<std::size_t>(free_var)] = true;
  for (Index c = 0; c < free_var; ++c) r.passive[static_cast<std::size_t>(c)] = start(c) > 0;
  const double tol = 1e-11 * std::max(1.0, g.cwiseAbs().maxCoeff());
  auto solve_passive = [&](VectorXd& z) {
    std::vector<Index> P;
    for (Index c = 0; c < m; ++c)
      if (r.passive[static_cast<std::size_t>(c)]) P.push_back(c);
    MatrixXd Qp(idx(P.size()), idx(P.size()));
    VectorXd gp(idx(P.size()));
    for (std::size_t a = 0; a < P.size(); ++a) {
      gp(idx(a)) = g(P[a]);
      for (std::size_t b = 0; b < P.size(); ++b) Qp(idx(a), idx(b)) = Q(P[a], P[b]);
    }
    const VectorXd zp = Qp.ldlt().solve(gp);
    z.setZero(m);
    for (std::size_t a = 0; a < P.size(); ++a) z(P[a]) = zp(idx(a));
  };
  VectorXd z;
  const int max_iter = 10 * static_cast<int>(m) + 100;
  bool need_add = false;
  while (r.iterations++ < max_iter) {
    if (need_add) {
      const VectorXd grad = g - Q * r.w;  // negative gradient
      Index best = -1;
      double best_val = tol;
      for (Index c = 0; c < free_var; ++c)
        if (!r.passive[static_cast<std::size_t>(c)] && grad(c) > best_val) {
          best_val = grad(c);
          best = c;
        }
      if (best < 0) break;  // KKT conditions hold
      r.passive[static_cast<std::size_t>(best)] = true;
    }
    solve_passive(z);
    double alpha = 1.0;
    for (Index c = 0; c < free_var; ++c)
      if (r.passive[static_cast<std::size_t>(c)] && z(c) <= 0.0) {
        const double denom = r.w(c) - z(c);
        alpha = std::min(alpha, denom > 0 ? r.w(c) / denom : 0.0);
      }
    r.w += alpha * (z - r.w);
    if (alpha >= 1.0) {
      need_add = true;
      continue;
    }
    for (Index c = 0; c < free_var; ++c)
      if (r.passive[static_cast<std::size_t>(c)] && r.w(c) <= 1e-14 * (1.0 + std::fabs(z(c)))) {
        r.passive[static_cast<std::size_t>(c)] = false;
        r.w(c) = 0.0;
      }
    need_add = false;
  }
  for (Index c = 0; c < free_var; ++c) r.w(c) = std::max(0.0, r.w(c));
  return r;
}

}  // namespace

LsqFitResult fit_preisach_lsq(std::span<const double> x, std::span<const double> y, const Grid& grid, const LsqFitOptions& opt) {
  check_fit_record(x, y, grid, 48);
  const std::size_t nodes = grid.node_count(), cells = grid.cell_count();
  const auto N = static_cast<double>(x.size());
  // Normal equations in node space, with the offset as the last unknown.
  MatrixXd G = MatrixXd::Zero(idx(nodes) + 1, idx(nodes) + 1);
  VectorXd b = VectorXd::Zero(idx(nodes) + 1);
  double yy = 0.0;
  const auto rows = preisach_regressors(grid, x);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    std::vector<RegressorTerm> row = rows[k];
    row.push_back(RegressorTerm{nodes, 1.0});
    for (const auto& s : row) {
      b(idx(s.node)) += s.weight * y[k];
      for (const auto& t : row) G(idx(s.node), idx(t.node)) += s.weight * t.weight;
    }
    yy += y[k] * y[k];
  }
  const MatrixXd P = cumulative_map(grid);
  const MatrixXd H = P.transpose() * G * P;
  const VectorXd g = P.transpose() * b;
  MatrixXd L = smoothing(grid);
  const double trH = std::max(H.trace(), 1e-300);
  L *= trH / std::max(L.trace(), 1e-300);

  // GCV on the unconstrained problem via H v = θ B v, B = H + L + εI, VᵀBV = I.
  const Index m = H.rows();
  MatrixXd B = H + L;
  B.diagonal().array() += 1e-10 * trH / static_cast<double>(m);
  Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> eig(H, B);
  const VectorXd theta = eig.eigenvalues().cwiseMax(0.0).cwiseMin(1.0);
  const MatrixXd& V = eig.eigenvectors();
  const VectorXd Vtg = V.transpose() * g;
  auto unconstrained = [&](double lambda, double& trace) {
    const VectorXd d = (theta.array() + lambda * (1.0 - theta.array())).max(1e-300);
    trace = (theta.array() / d.array()).sum();
    return VectorXd(V * (Vtg.array() / d.array()).matrix());
  };
  auto rss_of = [&](const VectorXd& w) { return std::max(0.0, yy - 2.0 * w.dot(g) + w.dot(H * w)); };

  LsqFitResult r;
  double best_lambda = opt.lambda, best_gcv = 0.0, trace = 0.0;
  if (best_lambda < 0.0) {
    best_gcv = std::numeric_limits<double>::infinity();
    for (int k = 0; k < opt.gcv_points; ++k) {
      const double lambda = std::pow(10.0, -10.0 + 12.0 * k / std::max(1, opt.gcv_points - 1));
      const VectorXd w = unconstrained(lambda, trace);
      const double denom = N - trace;
      const double gcv = denom > 0.5 ? N * rss_of(w) / (denom * denom) : std::numeric_limits<double>::infinity();
      if (gcv < best_gcv) {
        best_gcv = gcv;
        best_lambda = lambda;
      }
    }
  }
  const VectorXd start = unconstrained(best_lambda, trace);
  const MatrixXd Q = H + best_lambda * L;
  const ActiveSetResult sol = solve_nonnegative(Q, g, start);

  const VectorXd F = P * sol.w;
  std::vector<double> values(nodes);
  for (std::size_t k = 0; k < nodes; ++k) values[k] = F(idx(k));
  r.force_offset = sol.w(idx(cells));
  r.table = EverettTable(grid, std::move(values), r.force_offset);
  r.lambda = best_lambda;
  r.gcv = best_gcv;
  r.active_set_iterations = sol.iterations;

  // Residuals from the fitted table run through the model itself.
  PreisachModel model(r.table);
  double ss = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double e = model.step(x[k]) - y[k];
    ss += e * e;
    r.max_residual = std::max(r.max_residual, std::fabs(e));
  }
  r.rms_residual = std::sqrt(ss / N);

  // Uncertainty on the free (passive) set: cov = σ² Q⁻¹ H Q⁻¹, σ² = RSS / (N - edf).
  std::vector<Index> Pset;
  for (Index c = 0; c < m; ++c)
    if (sol.passive[static_cast<std::size_t>(c)]) Pset.push_back(c);
  MatrixXd Qp(idx(Pset.size()), idx(Pset.size())), Hp(idx(Pset.size()), idx(Pset.size()));
  for (std::size_t a = 0; a < Pset.size(); ++a)
    for (std::size_t c = 0; c < Pset.size(); ++c) {
      Qp(idx(a), idx(c)) = Q(Pset[a], Pset[c]);
      Hp(idx(a), idx(c)) = H(Pset[a], Pset[c]);
    }
  const auto ldlt = Qp.ldlt();
  const MatrixXd QinvH = ldlt.solve(Hp);
  r.effective_parameters = QinvH.trace();
  const double sigma2 = ss / std::max(1.0, N - r.effective_parameters);
  const MatrixXd cov = sigma2 * ldlt.solve(QinvH.transpose()).transpose();
  r.cell_weight.assign(cells, 0.0);
  r.cell_sigma.assign(cells, 0.0);
  for (std::size_t c = 0; c < cells; ++c) r.cell_weight[c] = sol.w(idx(c));
  for (std::size_t a = 0; a < Pset.size(); ++a)
    if (Pset[a] < idx(cells)) r.cell_sigma[static_cast<std::size_t>(Pset[a])] = std::sqrt(std::max(0.0, cov(idx(a), idx(a))));
  for (std::size_t c = 0; c < cells; ++c) r.cells_at_bound += sol.passive[c] ? 0U : 1U;
  return r;
}

}  // namespace hystlab::models
