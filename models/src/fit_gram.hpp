#pragma once
// The data term of the least-squares fit in node space, G = Aᵀ M A, formed once per training mask
// from the record's turning-point structure (private to hystlab::models).
//
// Why: a conjugate-gradient step through the operator costs two passes over every sample
// (A v, then Aᵀ r); through G it costs one pass over G's non-zeros, and G is small where the
// grid is: a node pairs only with the nodes it shares a sample's memory with. Measured on
// bench_fit's random walk at 10^5 samples (stop 42): a product with G 0.019 ms at n = 24 and
// 0.098 ms at n = 48 against 0.74 and 0.70 ms through the operator; the whole `auto` fit 8.35 ->
// 0.30 s and 24.7 -> 2.4 s (docs/MODELS_IMPLEMENTATION.md has the rest). Where G would hold more
// non-zeros than a step through the operator touches (fine grids on records rich in turning
// points), it is not formed and the operator is used, so memory stays O(samples + cells).
//
// Only the lower triangle is stored (an entry below the diagonal serves its row and its column in
// one read: the product is bound by memory traffic). The force offset is node `nodes()` (a column
// of ones). Sample k's row of A is the held terms alive at k plus its live stencil, so G = Σ_k M_k rowₖᵀ rowₖ splits into
//  - held × held: two terms alive at once have nested intervals (the memory is a stack), so the pair
//    counts the inner one's training samples: one sweep over the terms sorted by start;
//  - held × live and live × live: over runs of samples with the same stencil nodes and the same
//    terms alive, the stencil weights summed once per run.
#include <Eigen/SparseCore>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "hystlab/models/preisach_operator.hpp"

namespace hystlab::models::fit {

// The most entries (lower triangle) for which a product with G is cheaper than a pass through the
// operator (A v, then Aᵀ r). See its definition for the measurement.
[[nodiscard]] std::size_t gram_limit(const PreisachOperator& op) noexcept;

class NodeGram {
 public:
  // mask[k] weighs sample k (1 training, 0 held out). Not formed (formed() false) when its lower
  // triangle would hold more than max_nonzeros entries.
  NodeGram(const PreisachOperator& op, std::span<const double> mask, std::size_t max_nonzeros);

  [[nodiscard]] bool formed() const noexcept { return formed_; }
  [[nodiscard]] std::size_t size() const noexcept { return static_cast<std::size_t>(g_.rows()); }          // nodes + 1
  [[nodiscard]] std::size_t nonzeros() const noexcept { return static_cast<std::size_t>(g_.nonZeros()); }  // lower triangle
  [[nodiscard]] std::size_t bytes() const noexcept { return nonzeros() * (sizeof(double) + sizeof(std::int32_t)) + (size() + 1) * sizeof(std::int32_t); }
  // out = G v; v and out have size() entries.
  void apply(std::span<const double> v, std::span<double> out) const;
  [[nodiscard]] double diagonal(std::size_t node) const { return g_.coeff(static_cast<Index>(node), static_cast<Index>(node)); }
  // G of this mask minus G of a part of it (a held-out block): the fold's matrix without a pass
  // over the samples. Formed when both are.
  [[nodiscard]] NodeGram minus(const NodeGram& part) const;
  // The diagonal of Pᵀ G P (cell space, the offset left out): a pair of nodes shares the cells
  // p <= min(i), q > max(j), so each entry of G is added at node (min i, max j) and summed over
  // those cells as nodes_to_cells_transpose sums.
  [[nodiscard]] std::vector<double> cell_diagonal(const Grid& grid) const;

 private:
  NodeGram() = default;
  using Index = std::int32_t;
  Eigen::SparseMatrix<double, Eigen::RowMajor, Index> g_;
  bool formed_ = false;
};

}  // namespace hystlab::models::fit
