#pragma once
// The Preisach model's output on one input record as a linear map of its table, applied without
// ever forming a matrix: out[k] = Σ_node A[k][node] F[node] (MODELS.md §1, Eqs. 6-7).
//
// Why not rows or a Gram matrix: the row of sample k holds the interpolation stencils of every
// turning point in the memory, so the dense fit's Gram matrix costs Σ_k |row_k|² to build and
// (n²/2)² doubles to hold (3.2 GB at n = 200). But a turning point's terms stay the same from the
// sample that pushes it on the memory stack to the sample that wipes it out, so the whole record is
// a list of terms that are each alive over an interval of samples, plus the one stencil of the
// moving input per sample. A v and Aᵀ u then cost O(terms + samples) with difference arrays and
// prefix sums, and memory is O(samples).
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "hystlab/models/grid.hpp"

namespace hystlab::models {

class PreisachOperator {
 public:
  // Throws std::invalid_argument for a non-finite input or more than 2^32 - 2 samples.
  PreisachOperator(const Grid& grid, std::span<const double> input);

  [[nodiscard]] const Grid& grid() const noexcept { return grid_; }
  [[nodiscard]] std::size_t samples() const noexcept { return live_.size(); }
  [[nodiscard]] std::size_t nodes() const noexcept { return grid_.node_count(); }
  [[nodiscard]] std::size_t held_terms() const noexcept { return held_.size(); }
  [[nodiscard]] std::size_t memory_bytes() const noexcept;

  // out[k] = Σ_node A[k][node] v[node]; v.size() == nodes(), out.size() == samples().
  void apply(std::span<const double> v, std::span<double> out) const;
  // g[node] = Σ_k A[k][node] u[k]; u.size() == samples(), g.size() == nodes().
  void apply_transpose(std::span<const double> u, std::span<double> g) const;
  // The same with the caller's buffer for the prefix sums (resized to samples() + 1), so a solver
  // calling it every step allocates nothing.
  void apply_transpose(std::span<const double> u, std::span<double> g, std::vector<double>& prefix) const;

  struct HeldTerm {  // weight * F[node] is part of the output for samples start <= k < end
    std::uint32_t node;
    std::uint32_t start;
    std::uint32_t end;
    double weight;
  };
  struct LiveStencil {  // the moving input's term at one sample (unused slots: weight 0)
    std::array<std::uint32_t, 4> node;
    std::array<double, 4> weight;
  };
  // The terms themselves, for the node-space Gram matrix (fit_gram.hpp). A turning point's terms
  // live from the sample that pushes it on the memory stack to the one that wipes it out, so their
  // intervals are nested or disjoint, never crossing.
  [[nodiscard]] std::span<const HeldTerm> held() const noexcept { return held_; }
  [[nodiscard]] std::span<const LiveStencil> live() const noexcept { return live_; }

 private:
  Grid grid_;
  std::vector<HeldTerm> held_;
  std::vector<LiveStencil> live_;
};

}  // namespace hystlab::models
