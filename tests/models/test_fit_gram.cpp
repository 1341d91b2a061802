// Issue 41: the node-space Gram matrix of the least-squares fit equals the operator's Aᵀ M A.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "../../models/src/fit_gram.hpp"
#include "../../models/src/fit_system.hpp"
#include "hystlab/models/preisach_operator.hpp"
#include "test_support.hpp"

using namespace hystlab::models;

namespace {

// Ramps between random turning points with small random steps (minor loops nested in each other),
// some samples repeated (the input at rest), some beyond the grid (clamped).
std::vector<double> walk(std::mt19937_64& rng, const Grid& g, int reversals) {
  auto x = hystlab::test::random_ramps(rng, g.lo, g.hi, reversals, g.step() / 3.0);
  std::normal_distribution<double> jitter(0.0, g.step() / 4.0);
  for (std::size_t k = 1; k + 1 < x.size(); k += 3) x[k] += jitter(rng);
  for (std::size_t k = 5; k + 1 < x.size(); k += 17) x[k] = x[k - 1];
  x.push_back(g.hi + 1.0);
  x.push_back(0.5 * (g.lo + g.hi));
  return x;
}

// [Pᵀ Aᵀ M (A P w + c); Σ M (A P w + c)] through the operator.
std::vector<double> reference(const PreisachOperator& op, std::span<const double> mask, std::span<const double> u) {
  const Grid& g = op.grid();
  const std::size_t cells = g.cell_count();
  std::vector<double> nodes(op.nodes()), pred(op.samples()), back(op.nodes()), out(cells + 1);
  fit::cells_to_nodes(g, u.first(cells), nodes);
  op.apply(nodes, pred);
  double sum = 0.0;
  for (std::size_t k = 0; k < pred.size(); ++k) {
    pred[k] = mask[k] * (pred[k] + u[cells]);
    sum += pred[k];
  }
  op.apply_transpose(pred, back);
  fit::nodes_to_cells_transpose(g, back, std::span(out).first(cells));
  out[cells] = sum;
  return out;
}

}  // namespace

TEST_CASE("the node-space Gram matrix applies the data term exactly as the operator does, with any training mask") {
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    CAPTURE(seed);
    std::mt19937_64 rng(seed);
    const Grid g = Grid::make(-1.0, 3.0, 2 + static_cast<int>(seed % 6) * 3);
    const auto x = walk(rng, g, 20 + static_cast<int>(seed) * 5);
    const PreisachOperator op(g, x);
    // Seeds 1-4 train on everything, 5-8 hold out a contiguous block (a fold), 9-12 a random half.
    std::vector<double> mask(x.size(), 1.0);
    std::bernoulli_distribution half(0.5);
    for (std::size_t k = 0; k < mask.size(); ++k) {
      if (seed > 4 && seed <= 8) mask[k] = k >= x.size() / 3 && k < x.size() / 2 ? 0.0 : 1.0;
      if (seed > 8) mask[k] = half(rng) ? 1.0 : 0.0;
    }
    const fit::NodeGram gram(op, mask, std::size_t{1} << 30);
    REQUIRE(gram.formed());
    CHECK(gram.size() == op.nodes() + 1);
    fit::NormalSystem sys(op, std::vector<double>(x.size(), 0.0), mask);
    REQUIRE(sys.through_gram());
    // Pᵀ G P's diagonal (it scales λ and preconditions the faces) against Q's columns at λ = 0.
    const auto diag = gram.cell_diagonal(g);
    REQUIRE(diag.size() == g.cell_count());
    for (std::size_t c = 0; c < g.cell_count(); ++c) {
      std::vector<double> e(g.cell_count() + 1, 0.0), col(e.size());
      e[c] = 1.0;
      sys.apply(e, col);
      CAPTURE(c);
      CHECK(diag[c] == doctest::Approx(col[c]).epsilon(1e-12));
    }
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (int probe = 0; probe < 3; ++probe) {
      std::vector<double> u(g.cell_count() + 1), got(u.size());
      for (double& v : u) v = unit(rng);
      sys.apply(u, got);
      const auto want = reference(op, mask, u);
      double scale = 0.0, worst = 0.0;
      for (std::size_t c = 0; c < u.size(); ++c) {
        scale = std::max(scale, std::fabs(want[c]));
        worst = std::max(worst, std::fabs(got[c] - want[c]));
      }
      CAPTURE(probe);
      CHECK(worst <= 1e-10 * scale);
    }
  }
}

TEST_CASE("the Gram matrix is not formed where it would be larger than the operator's work per step") {
  std::mt19937_64 rng(3);
  const Grid g = Grid::make(0.0, 4.0, 40);
  const auto x = walk(rng, g, 40);
  const PreisachOperator op(g, x);
  const std::vector<double> mask(x.size(), 1.0);
  const fit::NodeGram small(op, mask, 100);
  CHECK_FALSE(small.formed());
  CHECK(small.nonzeros() == 0);
  const fit::NodeGram big(op, mask, std::size_t{1} << 30);
  CHECK(big.formed());
  CHECK(big.nonzeros() > 100);
}
