#include "fit_system.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace hystlab::models::fit {
namespace {

double dot(std::span<const double> a, std::span<const double> b) {
  double s = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) s += a[k] * b[k];
  return s;
}

double norm_on(std::span<const double> a, std::span<const std::uint8_t> free) {
  double s = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (free.empty() || free[k] != 0) s += a[k] * a[k];
  return std::sqrt(s);
}

}  // namespace

void cells_to_nodes(const Grid& g, std::span<const double> w, std::span<double> nodes) {
  for (int i = 0; i <= g.n; ++i) nodes[Grid::index(i, i)] = 0.0;
  for (int i = 1; i <= g.n; ++i) {
    double row = 0.0;  // Σ_{q=j+1..i} w(i, q)
    for (int j = i - 1; j >= 0; --j) {
      row += w[Grid::cell_index(i, j + 1)];
      nodes[Grid::index(i, j)] = nodes[Grid::index(i - 1, j)] + row;
    }
  }
}

void nodes_to_cells_transpose(const Grid& g, std::span<const double> nodes, std::span<double> w) {
  // w(p, q) = Σ_{i >= p} Σ_{j < q} nodes(i, j): prefix sums along each row, accumulated upwards.
  std::vector<double> column(static_cast<std::size_t>(g.n) + 1, 0.0);
  for (int i = g.n; i >= 1; --i) {
    double prefix = 0.0;
    for (int q = 1; q <= i; ++q) {
      prefix += nodes[Grid::index(i, q - 1)];
      column[static_cast<std::size_t>(q)] += prefix;
      w[Grid::cell_index(i, q)] = column[static_cast<std::size_t>(q)];
    }
  }
}

void nodes_to_cells(const Grid& g, std::span<const double> nodes, std::span<double> w) {
  auto F = [&](int i, int j) { return j >= i ? 0.0 : nodes[Grid::index(i, j)]; };
  for (int p = 1; p <= g.n; ++p)
    for (int q = 1; q <= p; ++q) w[Grid::cell_index(p, q)] = F(p, q - 1) - F(p - 1, q - 1) - F(p, q) + F(p - 1, q);
}

void cells_to_nodes_inverse_transpose(const Grid& g, std::span<const double> w, std::span<double> nodes) {
  std::fill(nodes.begin(), nodes.end(), 0.0);
  auto add = [&](int i, int j, double v) {
    if (j < i) nodes[Grid::index(i, j)] += v;
  };
  for (int p = 1; p <= g.n; ++p)
    for (int q = 1; q <= p; ++q) {
      const double v = w[Grid::cell_index(p, q)];
      add(p, q - 1, v);
      add(p - 1, q - 1, -v);
      add(p, q, -v);
      add(p - 1, q, v);
    }
}

namespace {

// The diagonal of R = P⁻ᵀ L P⁻¹ (smoothing in node space), exactly: a node's footprint through
// P⁻¹, L and P⁻ᵀ reaches nodes at most 2 away in i and in j, so probing every 5th node in each
// direction at once (25 probes) reads each diagonal entry unmixed.
std::vector<double> node_smoothing_diagonal(const Grid& g) {
  constexpr int kSpacing = 5;
  std::vector<double> diag(g.node_count(), 0.0), e(g.node_count()), w(g.cell_count()), lw(g.cell_count()), back(g.node_count());
  for (int ci = 0; ci < kSpacing; ++ci)
    for (int cj = 0; cj < kSpacing; ++cj) {
      std::fill(e.begin(), e.end(), 0.0);
      for (int i = ci; i <= g.n; i += kSpacing)
        for (int j = cj; j < i; j += kSpacing) e[Grid::index(i, j)] = 1.0;
      nodes_to_cells(g, e, w);
      smoothing_apply(g, w, lw);
      cells_to_nodes_inverse_transpose(g, lw, back);
      for (int i = ci; i <= g.n; i += kSpacing)
        for (int j = cj; j < i; j += kSpacing) diag[Grid::index(i, j)] = back[Grid::index(i, j)];
    }
  return diag;
}

}  // namespace

void smoothing_apply(const Grid& g, std::span<const double> w, std::span<double> out) {
  std::fill(out.begin(), out.end(), 0.0);
  auto couple = [&](std::size_t a, std::size_t b) {
    const double d = w[a] - w[b];
    out[a] += d;
    out[b] -= d;
  };
  for (int p = 1; p <= g.n; ++p)
    for (int q = 1; q <= p; ++q) {
      if (p < g.n) couple(Grid::cell_index(p, q), Grid::cell_index(p + 1, q));
      if (q < p) couple(Grid::cell_index(p, q), Grid::cell_index(p, q + 1));
    }
}

std::vector<double> smoothing_diagonal(const Grid& g) {
  std::vector<double> d(g.cell_count(), 0.0);
  for (int p = 1; p <= g.n; ++p)
    for (int q = 1; q <= p; ++q) {
      if (p < g.n) {
        d[Grid::cell_index(p, q)] += 1.0;
        d[Grid::cell_index(p + 1, q)] += 1.0;
      }
      if (q < p) {
        d[Grid::cell_index(p, q)] += 1.0;
        d[Grid::cell_index(p, q + 1)] += 1.0;
      }
    }
  return d;
}

namespace {
std::vector<double> checked_mask(const PreisachOperator& op, std::span<const double> force, std::vector<double> mask) {
  if (mask.size() != op.samples() || force.size() != op.samples())
    throw std::invalid_argument("fit: the force record and the mask must have one value per sample");
  return mask;
}
}  // namespace

NormalSystem::NormalSystem(const PreisachOperator& op, std::span<const double> force, std::vector<double> mask)
    : NormalSystem(op, force, std::move(mask), nullptr) {}

NormalSystem::NormalSystem(const PreisachOperator& op, std::span<const double> force, std::vector<double> mask, std::shared_ptr<const NodeGram> gram)
    : op_(op), mask_(checked_mask(op, force, std::move(mask))), gram_(std::move(gram)), cells_(op.grid().cell_count()) {
  if (!gram_) gram_ = std::make_shared<const NodeGram>(op, mask_, gram_limit(op));
  if (gram_->size() != op.nodes() + 1) throw std::invalid_argument("fit: the Gram matrix is not of this record's grid");
  nodes_.assign(op.nodes(), 0.0);
  node_grad_.assign(op.nodes(), 0.0);
  samples_.assign(op.samples(), 0.0);
  cell_tmp_.assign(cells_, 0.0);
  rhs_.assign(size(), 0.0);
  pre_nodes_.assign(op.nodes(), 0.0);
  data_gradient(force, rhs_);
  if (gram_->formed()) {  // both diagonals exactly, from G
    data_diag_.assign(op.nodes(), 0.0);
    for (std::size_t a = 0; a < data_diag_.size(); ++a) data_diag_[a] = gram_->diagonal(a);
    cell_data_diag_ = gram_->cell_diagonal(op.grid());
    gram_in_.assign(gram_->size(), 0.0);
    gram_out_.assign(gram_->size(), 0.0);
  } else {
    estimate_diagonals();
  }
  offset_diag_ = 0.0;
  for (double m : mask_) offset_diag_ += m;
  offset_diag_ = std::max(offset_diag_, 1.0);
  smooth_diag_ = node_smoothing_diagonal(op.grid());
  cell_smooth_diag_ = smoothing_diagonal(op.grid());
  double smooth_trace = 0.0, data_trace = 0.0;
  for (std::size_t c = 0; c < cells_; ++c) {
    smooth_trace += cell_smooth_diag_[c];
    data_trace += cell_data_diag_[c];
  }
  trace_ratio_ = smooth_trace > 0.0 ? std::max(data_trace, 1e-300) / smooth_trace : 1.0;
  set_lambda(0.0);
}

void NormalSystem::estimate_diagonals() {
  // The data term's diagonal in node space, E[(Aᵀ M z)_a²] = Σ_k M_k A_ka² for z of random signs,
  // from 8 probes (without G it cannot be read off; ±50 % is plenty for a preconditioner). The
  // same probes mapped to cells give the trace that scales λ.
  constexpr int kProbes = 8;
  std::mt19937_64 rng(0x5eed);
  std::vector<double> z(op_.samples()), t(op_.nodes()), tw(cells_);
  data_diag_.assign(op_.nodes(), 0.0);
  cell_data_diag_.assign(cells_, 0.0);
  for (int probe = 0; probe < kProbes; ++probe) {
    for (std::size_t k = 0; k < z.size(); ++k) z[k] = mask_[k] * ((rng() & 1U) != 0U ? 1.0 : -1.0);
    op_.apply_transpose(z, t, prefix_);
    for (std::size_t a = 0; a < t.size(); ++a) data_diag_[a] += t[a] * t[a] / kProbes;
    nodes_to_cells_transpose(op_.grid(), t, tw);
    for (std::size_t c = 0; c < cells_; ++c) cell_data_diag_[c] += tw[c] * tw[c] / kProbes;
  }
}

void NormalSystem::set_lambda(double lambda) {
  lambda_scaled_ = lambda * trace_ratio_;
  const Grid& g = op_.grid();
  inv_diag_.assign(data_diag_.size(), 0.0);
  double largest = 0.0;
  for (std::size_t a = 0; a < inv_diag_.size(); ++a) largest = std::max(largest, data_diag_[a] + lambda_scaled_ * smooth_diag_[a]);
  for (int i = 0; i <= g.n; ++i)
    for (int j = 0; j < i; ++j) {
      const std::size_t a = Grid::index(i, j);
      inv_diag_[a] = 1.0 / std::max(data_diag_[a] + lambda_scaled_ * smooth_diag_[a], 1e-12 * largest + 1e-300);
    }
  inv_cell_diag_.assign(cells_, 0.0);
  largest = 0.0;
  for (std::size_t c = 0; c < cells_; ++c) largest = std::max(largest, cell_data_diag_[c] + lambda_scaled_ * cell_smooth_diag_[c]);
  for (std::size_t c = 0; c < cells_; ++c)
    inv_cell_diag_[c] = 1.0 / std::max(cell_data_diag_[c] + lambda_scaled_ * cell_smooth_diag_[c], 1e-12 * largest + 1e-300);
}

void NormalSystem::precondition(std::span<const double> r, std::span<double> z, bool on_face) const {
  const Grid& g = op_.grid();
  z[cells_] = r[cells_] / offset_diag_;
  if (on_face) {
    for (std::size_t c = 0; c < cells_; ++c) z[c] = inv_cell_diag_[c] * r[c];
    return;
  }
  cells_to_nodes_inverse_transpose(g, r.first(cells_), pre_nodes_);
  for (std::size_t a = 0; a < pre_nodes_.size(); ++a) pre_nodes_[a] *= inv_diag_[a];
  nodes_to_cells(g, pre_nodes_, z.first(cells_));
}

void NormalSystem::predict(std::span<const double> u, std::span<double> out) const {
  cells_to_nodes(op_.grid(), u.first(cells_), nodes_);
  op_.apply(nodes_, out);
  for (double& v : out) v += u[cells_];
}

void NormalSystem::data_gradient(std::span<const double> r, std::span<double> out) const {
  double sum = 0.0;
  for (std::size_t k = 0; k < r.size(); ++k) {
    samples_[k] = mask_[k] * r[k];
    sum += samples_[k];
  }
  op_.apply_transpose(samples_, node_grad_, prefix_);
  nodes_to_cells_transpose(op_.grid(), node_grad_, out.first(cells_));
  out[cells_] = sum;
}

void NormalSystem::apply(std::span<const double> u, std::span<double> out) const {
  if (gram_->formed()) {
    const std::size_t nodes = op_.nodes();
    cells_to_nodes(op_.grid(), u.first(cells_), std::span<double>(gram_in_).first(nodes));
    gram_in_[nodes] = u[cells_];
    gram_->apply(gram_in_, gram_out_);
    nodes_to_cells_transpose(op_.grid(), std::span<const double>(gram_out_).first(nodes), out.first(cells_));
    out[cells_] = gram_out_[nodes];
  } else {
    apply_through_operator(u, out);
  }
  if (lambda_scaled_ > 0.0) {
    smoothing_apply(op_.grid(), u.first(cells_), cell_tmp_);
    for (std::size_t c = 0; c < cells_; ++c) out[c] += lambda_scaled_ * cell_tmp_[c];
  }
}

void NormalSystem::apply_through_operator(std::span<const double> u, std::span<double> out) const {
  predict(u, samples_);
  std::vector<double>& pred = samples_;
  for (std::size_t k = 0; k < pred.size(); ++k) pred[k] *= mask_[k];
  op_.apply_transpose(pred, node_grad_, prefix_);
  nodes_to_cells_transpose(op_.grid(), node_grad_, out.first(cells_));
  double sum = 0.0;
  for (double v : pred) sum += v;
  out[cells_] = sum;
}

std::size_t NormalSystem::scratch_bytes() const noexcept {
  return (mask_.capacity() + samples_.capacity() + nodes_.capacity() + node_grad_.capacity() + cell_tmp_.capacity() + rhs_.capacity() + data_diag_.capacity() +
          smooth_diag_.capacity() + inv_diag_.capacity() + pre_nodes_.capacity() + cell_data_diag_.capacity() + cell_smooth_diag_.capacity() +
          inv_cell_diag_.capacity() + prefix_.capacity() + gram_in_.capacity() + gram_out_.capacity()) *
             sizeof(double) +
         (gram_->formed() ? gram_->bytes() : 0);
}

SolveStats solve_on_face(const NormalSystem& s, std::span<const double> b, std::vector<double>& u, std::span<const std::uint8_t> free, double tol,
                         int max_iterations, bool stop_at_bound) {
  const std::size_t m = s.size(), cells = s.cells();
  auto on = [&](std::size_t c) { return free.empty() || free[c] != 0; };
  std::vector<double> r(m), z(m), p(m), q(m);
  s.apply(u, q);
  for (std::size_t c = 0; c < m; ++c) r[c] = on(c) ? b[c] - q[c] : 0.0;
  double bnorm = norm_on(b, free);
  if (bnorm == 0.0) bnorm = 1.0;
  auto precondition = [&] {
    s.precondition(r, z, !free.empty());
    for (std::size_t c = 0; c < m; ++c)
      if (!on(c)) z[c] = 0.0;
  };
  precondition();
  p = z;
  double rz = dot(r, z);
  SolveStats st;
  for (; st.iterations < max_iterations; ++st.iterations) {
    if (norm_on(r, {}) <= tol * bnorm) {
      st.converged = true;
      return st;
    }
    s.apply(p, q);
    for (std::size_t c = 0; c < m; ++c)
      if (!on(c)) q[c] = 0.0;
    const double pq = dot(p, q);
    if (!(pq > 0.0)) return st;  // no curvature left along p (converged to rounding)
    const double alpha = rz / pq;
    if (stop_at_bound) {
      double to_bound = std::numeric_limits<double>::infinity();
      std::size_t hit = m;
      for (std::size_t c = 0; c < cells; ++c)
        if (on(c) && p[c] < 0.0 && std::max(0.0, u[c]) / -p[c] < to_bound) {
          to_bound = std::max(0.0, u[c]) / -p[c];
          hit = c;
        }
      if (to_bound < alpha) {
        for (std::size_t c = 0; c < m; ++c) u[c] += to_bound * p[c];
        for (std::size_t c = 0; c < cells; ++c) u[c] = std::max(0.0, u[c]);
        u[hit] = 0.0;
        ++st.iterations;
        return st;
      }
    }
    for (std::size_t c = 0; c < m; ++c) {
      u[c] += alpha * p[c];
      r[c] -= alpha * q[c];
    }
    precondition();
    const double rz_next = dot(r, z), beta = rz_next / rz;
    rz = rz_next;
    for (std::size_t c = 0; c < m; ++c) p[c] = z[c] + beta * p[c];
  }
  return st;
}

SolveStats solve_signed(const NormalSystem& s, std::span<const double> b, std::vector<double>& u, double tol, int max_iterations) {
  return solve_on_face(s, b, u, {}, tol, max_iterations, false);
}

namespace {

// One projected-gradient step with backtracking (Armijo along the projection arc). Returns false
// when the projected gradient is already below the tolerance (u is a KKT point).
bool gradient_projection_step(const NormalSystem& s, std::span<const double> b, std::vector<double>& u, double tol_abs) {
  const std::size_t m = s.size(), cells = s.cells();
  std::vector<double> g(m), d(m), qd(m), trial(m), step(m);
  s.apply(u, g);
  double pg2 = 0.0;
  for (std::size_t c = 0; c < m; ++c) {
    g[c] -= b[c];
    const bool blocked = c < cells && u[c] <= 0.0 && g[c] > 0.0;
    d[c] = blocked ? 0.0 : -g[c];
    pg2 += d[c] * d[c];
  }
  if (std::sqrt(pg2) <= tol_abs) return false;
  s.apply(d, qd);
  const double curvature = dot(d, qd);
  double alpha = curvature > 0.0 ? pg2 / curvature : 1.0;
  for (int backtrack = 0; backtrack < 40; ++backtrack, alpha *= 0.5) {
    for (std::size_t c = 0; c < m; ++c) {
      trial[c] = u[c] + alpha * d[c];
      if (c < cells) trial[c] = std::max(0.0, trial[c]);
      step[c] = trial[c] - u[c];
    }
    s.apply(step, qd);
    const double slope = dot(g, step);
    if (slope + 0.5 * dot(step, qd) <= 1e-4 * slope) break;
  }
  u = trial;
  return true;
}

}  // namespace

SolveStats solve_monotone(const NormalSystem& s, std::span<const double> b, std::vector<double>& u, double tol, int max_iterations,
                          std::vector<std::uint8_t>& free_out) {
  const std::size_t m = s.size(), cells = s.cells();
  for (std::size_t c = 0; c < cells; ++c) u[c] = std::max(0.0, u[c]);
  double bnorm = norm_on(b, {});
  if (bnorm == 0.0) bnorm = 1.0;
  SolveStats st;
  free_out.assign(m, 1);
  while (st.iterations < max_iterations) {
    // Gradient projection until the set of cells at the bound settles (or 5 steps).
    std::size_t at_bound = cells + 1;
    bool moved = true;
    for (int k = 0; k < 5 && moved; ++k) {
      moved = gradient_projection_step(s, b, u, tol * bnorm);
      st.iterations += moved ? 1 : 0;
      std::size_t now = 0;
      for (std::size_t c = 0; c < cells; ++c) now += u[c] <= 0.0 ? 1U : 0U;
      if (now == at_bound) break;
      at_bound = now;
    }
    if (!moved) {
      st.converged = true;
      break;
    }
    for (std::size_t c = 0; c < m; ++c) free_out[c] = (c == cells || u[c] > 0.0) ? 1 : 0;
    const SolveStats face = solve_on_face(s, b, u, free_out, tol, max_iterations - st.iterations, true);
    st.iterations += face.iterations;
  }
  for (std::size_t c = 0; c < cells; ++c) u[c] = std::max(0.0, u[c]);  // no -1e-17 left by rounding
  for (std::size_t c = 0; c < m; ++c) free_out[c] = (c == cells || u[c] > 0.0) ? 1 : 0;
  return st;
}

}  // namespace hystlab::models::fit
