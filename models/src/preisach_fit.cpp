#include "hystlab/models/preisach_fit.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>

#include "fit_record.hpp"
#include "fit_system.hpp"
#include "hystlab/models/preisach_model.hpp"

namespace hystlab::models {
namespace {

using fit::NormalSystem;

// λ tried by the cross-validation, largest first: each solve starts from the smoother solution of
// the λ before it, which is close (warm start).
constexpr double kLambdas[] = {1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7};
constexpr double kCvTolerance = 1e-6;
constexpr int kMaxIterations = 4000;
// Above this many samples, λ and the prior are chosen (and σ estimated) on the record thinned to
// about this many, every turning point kept; the chosen prior is then fitted on every sample.
constexpr std::size_t kSelectionSamples = 200000;

// Every turning point of the input (the last sample before its direction reverses, so that the
// Preisach memory at every kept sample is the one of the whole record), the first and last
// samples, and every d-th sample in between.
struct Thinned {
  std::vector<double> x, y;
};
Thinned thin(std::span<const double> x, std::span<const double> y, std::size_t target) {
  const std::size_t n = x.size(), d = (n + target - 1) / target;
  Thinned t;
  int dir = 0;
  for (std::size_t k = 0; k < n; ++k) {
    bool keep = k == 0 || k + 1 == n || k % d == 0;
    if (k + 1 < n && x[k + 1] != x[k]) {
      const int next = x[k + 1] > x[k] ? 1 : -1;
      keep = keep || (dir != 0 && next != dir);  // x[k] is an extreme: the input turns after it
      dir = next;
    }
    if (keep) t.x.push_back(x[k]), t.y.push_back(y[k]);
  }
  return t;
}

void validate(std::span<const double> x, std::span<const double> y, const Grid& grid, const PreisachFitOptions& o) {
  if (o.folds < 2 || o.folds > 20) throw std::invalid_argument("fit: folds must be from 2 to 20");
  if (std::isnan(o.lambda) || o.lambda > 1e6)
    throw std::invalid_argument("fit: lambda must be a number from 0 to 1e6 (or negative to choose it by cross-validation)");
  if (!(o.tolerance > 0.0 && o.tolerance <= 0.1)) throw std::invalid_argument("fit: tolerance must be in (0, 0.1]");
  if (o.uncertainty_probes < 0 || o.uncertainty_probes > 1000) throw std::invalid_argument("fit: uncertainty_probes must be from 0 to 1000");
  (void)Grid::make(grid.lo, grid.hi, grid.n);  // a grid not built by Grid::make is checked the same way
  check_fit_record(x, y, grid, o.max_subdivisions);
}

struct Solved {
  std::vector<double> u;
  std::vector<std::uint8_t> free;
  int iterations = 0;
  bool converged = true;
};

void solve(const NormalSystem& s, FitPrior prior, double tol, Solved& out) {
  fit::SolveStats st;
  if (prior == FitPrior::monotone) {
    st = fit::solve_monotone(s, s.rhs(), out.u, tol, kMaxIterations, out.free);
  } else {
    st = fit::solve_signed(s, s.rhs(), out.u, tol, kMaxIterations);
    out.free.assign(s.size(), 1);
  }
  out.iterations += st.iterations;
  out.converged = st.converged;
}

// Fold f holds out the f-th of `folds` contiguous blocks.
std::pair<std::size_t, std::size_t> block(std::size_t samples, int f, int folds) {
  return {samples * static_cast<std::size_t>(f) / static_cast<std::size_t>(folds), samples * static_cast<std::size_t>(f + 1) / static_cast<std::size_t>(folds)};
}

std::vector<double> fold_mask(std::size_t samples, int f, int folds) {
  const auto [begin, end] = block(samples, f, folds);
  std::vector<double> mask(samples, 1.0);
  std::fill(mask.begin() + static_cast<std::ptrdiff_t>(begin), mask.begin() + static_cast<std::ptrdiff_t>(end), 0.0);
  return mask;
}

// The node-space Gram matrices of the selection record (fit_gram.hpp), formed once and shared by
// both priors: the whole record's, and each fold's as the whole minus its held-out block (the
// blocks together cost one pass over the samples). Empty when G would cost more than the operator.
struct Grams {
  std::shared_ptr<const fit::NodeGram> whole;
  std::vector<std::shared_ptr<const fit::NodeGram>> fold;
};

Grams form_grams(const PreisachOperator& op, int folds) {
  Grams g;
  const std::size_t limit = fit::gram_limit(op);
  g.whole = std::make_shared<const fit::NodeGram>(op, std::vector<double>(op.samples(), 1.0), limit);
  if (!g.whole->formed()) return Grams{};
  for (int f = 0; f < folds; ++f) {
    std::vector<double> in_block = fold_mask(op.samples(), f, folds);
    for (double& m : in_block) m = 1.0 - m;
    const fit::NodeGram part(op, in_block, limit);
    g.fold.push_back(std::make_shared<const fit::NodeGram>(g.whole->minus(part)));
  }
  return g;
}

struct CrossValidation {
  std::vector<double> rms;                  // held-out RMS per λ
  std::vector<std::vector<double>> solved;  // per λ, the last fold's solution (empty: not reached)
};

// Held-out RMS for every λ of kLambdas: fold f trains on all samples but block f and is scored on
// block f, whose memory state comes from the whole record before it.
CrossValidation cross_validate(const PreisachOperator& op, std::span<const double> y, FitPrior prior, int folds, std::span<const double> lambdas,
                               const Grams& grams, int& iterations) {
  const std::size_t N = op.samples();
  std::vector<double> sse(lambdas.size(), 0.0), pred(N);
  CrossValidation cv{{}, std::vector<std::vector<double>>(lambdas.size())};
  for (int f = 0; f < folds; ++f) {
    const auto [begin, end] = block(N, f, folds);
    NormalSystem s(op, y, fold_mask(N, f, folds), grams.fold.empty() ? nullptr : grams.fold[static_cast<std::size_t>(f)]);
    Solved sol{std::vector<double>(s.size(), 0.0), {}, 0};
    // Down the λ path (largest first, warm started) until this block's error has not improved by
    // 0.1 % at two λ in a row: the smallest λ are the costliest solves, and past the minimum (or on
    // a flat curve: a prior whose error is the model's, not the noise's) they only fit the noise.
    // The λ not reached score +∞ (never chosen). Measured at n = 100 on 10^6 samples: 431 s with
    // every λ on every sample, 36 s with this and the thinned selection record.
    double best = std::numeric_limits<double>::infinity();
    int rising = 0;
    for (std::size_t l = 0; l < lambdas.size(); ++l) {
      if (rising >= 2) {
        sse[l] = std::numeric_limits<double>::infinity();
        continue;
      }
      // Warm starts: a fold's solution at a λ is close to the previous fold's at the same λ (they
      // share all but two blocks), closer than to its own at the λ before. Measured at n = 48 on
      // 10^5 samples: the first λ of a fold took 700-800 steps from zero.
      if (!cv.solved[l].empty()) sol.u = cv.solved[l];
      s.set_lambda(lambdas[l]);
      solve(s, prior, kCvTolerance, sol);
      cv.solved[l] = sol.u;
      s.predict(sol.u, pred);
      double e = 0.0;
      for (std::size_t k = begin; k < end; ++k) e += (pred[k] - y[k]) * (pred[k] - y[k]);
      sse[l] += e;
      rising = e > best * (1 - 1e-3) ? rising + 1 : 0;
      best = std::min(best, e);
    }
    iterations += sol.iterations;
  }
  // A solve that went non-finite scores +∞: it can never be chosen.
  for (double& v : sse) v = std::isfinite(v) ? std::sqrt(v / static_cast<double>(N)) : std::numeric_limits<double>::infinity();
  cv.rms = std::move(sse);
  return cv;
}

// Per-cell σ and the effective number of parameters from random probes z of the samples:
// v = Q_F⁻¹ (Jᵀ z)_F has E[v∘v] = diag(Q_F⁻¹ H_F Q_F⁻¹) and E[(Jᵀz)·v] = tr(Q_F⁻¹ H_F) on the
// free set F, with the exact sandwich covariance σ² Q⁻¹ H Q⁻¹ of the dense fit as its mean.
void uncertainty(const NormalSystem& s, const Solved& sol, double rss, std::size_t samples, int probes, PriorFit& r, int& iterations) {
  const std::size_t m = s.size(), cells = s.cells();
  std::vector<double> var(m, 0.0), z(samples), jz(m);
  double edf = 0.0;
  std::mt19937_64 rng(0xc0ffee);
  for (int p = 0; p < probes; ++p) {
    for (double& v : z) v = (rng() & 1U) != 0U ? 1.0 : -1.0;
    s.data_gradient(z, jz);
    for (std::size_t c = 0; c < m; ++c)
      if (sol.free[c] == 0) jz[c] = 0.0;
    std::vector<double> v(m, 0.0);
    const bool all_free = std::all_of(sol.free.begin(), sol.free.end(), [](std::uint8_t f) { return f != 0; });
    iterations += fit::solve_on_face(s, jz, v, all_free ? std::span<const std::uint8_t>{} : sol.free, 1e-6, kMaxIterations, false).iterations;
    for (std::size_t c = 0; c < m; ++c) {
      var[c] += v[c] * v[c] / probes;
      edf += jz[c] * v[c] / probes;
    }
  }
  const double sigma2 = probes > 0 ? rss / std::max(1.0, static_cast<double>(samples) - edf) : 0.0;
  r.cell_sigma.assign(cells, 0.0);
  for (std::size_t c = 0; c < cells; ++c) r.cell_sigma[c] = std::sqrt(sigma2 * var[c]);
}

// A prior's fit on the whole record at its λ, with the solution kept for the σ probes.
struct FinalFit {
  PriorFit fit;
  Solved solved;
  double rss = 0.0;  // N², from the table run through the model
};

NormalSystem whole_record(const PreisachOperator& op, std::span<const double> y, double lambda, std::shared_ptr<const fit::NodeGram> gram = nullptr) {
  NormalSystem s(op, y, std::vector<double>(op.samples(), 1.0), std::move(gram));
  s.set_lambda(lambda);
  return s;
}

FinalFit final_fit(const PreisachOperator& op, std::span<const double> x, std::span<const double> y, FitPrior prior, double lambda, double tolerance,
                   const std::vector<double>* start = nullptr, std::shared_ptr<const fit::NodeGram> gram = nullptr) {
  const Grid& g = op.grid();
  FinalFit out;
  out.solved.u = start ? *start : std::vector<double>(g.cell_count() + 1, 0.0);
  solve(whole_record(op, y, lambda, std::move(gram)), prior, tolerance, out.solved);
  const Solved& sol = out.solved;
  PriorFit& r = out.fit;
  r.prior = prior;
  r.lambda = lambda;
  r.iterations = sol.iterations;
  r.converged = sol.converged;
  const std::size_t cells = g.cell_count();
  r.cell_weight.assign(sol.u.begin(), sol.u.begin() + static_cast<std::ptrdiff_t>(cells));
  r.force_offset = sol.u[cells];
  std::vector<double> values(g.node_count());
  fit::cells_to_nodes(g, r.cell_weight, values);
  r.table = EverettTable(g, std::move(values), r.force_offset);
  for (std::size_t c = 0; c < cells; ++c) {
    r.cells_at_bound += prior == FitPrior::monotone && sol.free[c] == 0 ? 1U : 0U;
    r.negative_cells += r.cell_weight[c] < 0.0 ? 1U : 0U;
  }
  // Residuals from the fitted table run through the model itself, not through the operator.
  PreisachModel model(r.table);
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double e = model.step(x[k]) - y[k];
    out.rss += e * e;
    r.max_residual = std::max(r.max_residual, std::fabs(e));
  }
  r.rms_residual = std::sqrt(out.rss / static_cast<double>(x.size()));
  r.cell_sigma.assign(cells, 0.0);
  return out;
}

// One prior: λ by cross-validation, or the given λ scored on the same held-out blocks (so `auto`
// still compares the priors on data they were not fitted to); then its fit on the whole record.
FinalFit fit_prior(const PreisachOperator& op, std::span<const double> x, std::span<const double> y, FitPrior prior, const PreisachFitOptions& o,
                   const Grams& grams) {
  const std::vector<double> lambdas = o.lambda < 0.0 ? std::vector<double>(std::begin(kLambdas), std::end(kLambdas)) : std::vector<double>{o.lambda};
  int cv_iterations = 0;
  CrossValidation cv = cross_validate(op, y, prior, o.folds, lambdas, grams, cv_iterations);
  std::vector<double>& rms = cv.rms;
  const auto best = static_cast<std::size_t>(std::min_element(rms.begin(), rms.end()) - rms.begin());
  if (!std::isfinite(rms[best])) throw std::invalid_argument("fit: every smoothing weight gave a non-finite error: the record cannot be fitted");
  // The whole record's solve starts from the last fold's solution at the chosen λ.
  FinalFit f = final_fit(op, x, y, prior, lambdas[best], o.tolerance, &cv.solved[best], grams.whole);
  f.fit.heldout_rms = rms[best];
  f.fit.cv_lambda = lambdas;
  f.fit.cv_rms = std::move(rms);
  f.fit.iterations += cv_iterations;
  return f;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

std::string describe(const PriorFit& f) {
  return std::string(to_string(f.prior)) + ": held-out RMS " + number(f.heldout_rms) + " N (λ " + number(f.lambda) + ")";
}

}  // namespace

std::string_view to_string(FitPrior p) noexcept {
  switch (p) {
    case FitPrior::signed_masses:
      return "signed";
    case FitPrior::monotone:
      return "monotone";
    case FitPrior::automatic:
      return "auto";
  }
  return "?";
}

FitPrior fit_prior_from_string(std::string_view s) {
  if (s == "signed") return FitPrior::signed_masses;
  if (s == "monotone") return FitPrior::monotone;
  if (s == "auto") return FitPrior::automatic;
  throw std::invalid_argument("prior: must be signed, monotone or auto, got '" + std::string(s) + "'");
}

PreisachFitResult fit_preisach(std::span<const double> x, std::span<const double> y, const Grid& grid, const PreisachFitOptions& o) {
  validate(x, y, grid, o);
  const auto t0 = std::chrono::steady_clock::now();
  // A long record: λ, the prior and σ from the thinned record (sel), the chosen prior's table from
  // every sample (op), started from the thinned record's solution.
  const bool thinned = x.size() > kSelectionSamples;
  const Thinned t = thinned ? thin(x, y, kSelectionSamples) : Thinned{};
  const std::span<const double> sx = thinned ? std::span<const double>(t.x) : x, sy = thinned ? std::span<const double>(t.y) : y;
  const PreisachOperator sel(grid, sx);
  PreisachFitResult result;
  result.selection_samples = sx.size();
  std::vector<FitPrior> priors;
  if (o.prior == FitPrior::automatic)
    priors = {FitPrior::signed_masses, FitPrior::monotone};
  else
    priors = {o.prior};
  const Grams grams = form_grams(sel, o.folds);
  std::vector<FinalFit> finals;
  for (const FitPrior prior : priors) finals.push_back(fit_prior(sel, sx, sy, prior, o, grams));
  std::size_t best = 0;
  for (std::size_t k = 1; k < finals.size(); ++k)
    if (finals[k].fit.heldout_rms < finals[best].fit.heldout_rms) best = k;
  // σ for the chosen prior only (its probes are the costly part after the cross-validation), on
  // the records the selection used: with s of N samples, the data's normal matrix is about s/N of
  // the whole record's, so the whole record's σ is about √(s/N) of it.
  PriorFit& chosen = finals[best].fit;
  if (o.uncertainty_probes > 0) {
    uncertainty(whole_record(sel, sy, chosen.lambda, grams.whole), finals[best].solved, finals[best].rss, sx.size(), o.uncertainty_probes, chosen,
                chosen.iterations);
    if (thinned)
      for (double& s : chosen.cell_sigma) s *= std::sqrt(static_cast<double>(sx.size()) / static_cast<double>(x.size()));
  }
  std::size_t op_bytes = sel.memory_bytes();
  if (thinned) {  // the chosen prior on every sample, at its λ, from the thinned solution
    const PreisachOperator op(grid, x);
    op_bytes = std::max(op_bytes, op.memory_bytes());
    FinalFit full = final_fit(op, x, y, chosen.prior, chosen.lambda, o.tolerance, &finals[best].solved.u);
    full.fit.heldout_rms = chosen.heldout_rms;
    full.fit.cv_lambda = chosen.cv_lambda;
    full.fit.cv_rms = chosen.cv_rms;
    full.fit.cell_sigma = chosen.cell_sigma;
    full.fit.iterations += chosen.iterations;
    finals[best] = std::move(full);
  }
  result.operator_bytes = op_bytes;
  for (FinalFit& f : finals) result.candidates.push_back(std::move(f.fit));
  if (result.candidates.size() > 1) {
    const PriorFit& w = result.candidates[best];
    const PriorFit& l = result.candidates[1 - best];
    result.reason = describe(w) + " against " + describe(l) + ": " + std::string(to_string(w.prior)) + " has the lower error on held-out blocks of the record";
  } else {
    result.reason = describe(result.candidates[0]) + " (prior " + std::string(to_string(o.prior)) + " as asked)";
  }
  for (const PriorFit& f : result.candidates)
    if (!f.converged) result.reason += "; WARNING: the " + std::string(to_string(f.prior)) + " solve stopped at its step limit before converging";
  result.chosen = result.candidates[best];
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // The operator, one system's scratch and a few solver vectors of the cells are alive at once.
  std::size_t gram_bytes = grams.whole ? grams.whole->bytes() : 0;
  for (const auto& f : grams.fold) gram_bytes += f->bytes();
  result.peak_bytes = op_bytes + gram_bytes + (7 * x.size() + 12 * (grid.cell_count() + 1) + 3 * grid.node_count()) * sizeof(double) +
                      (thinned ? sel.memory_bytes() + 2 * sx.size() * sizeof(double) : 0);
  return result;
}

}  // namespace hystlab::models
