#pragma once
// The FOT grid: the nodes δ_0 = δmin < δ_1 < ... < δ_n = δmax (MODELS.md §1). Uniform (n equal
// subdivisions of [lo, hi], the paper's) or with node positions of its own, refined where the
// user needs accuracy (near an operating preload, say): table format version 2.
#include <algorithm>
#include <cstddef>
#include <memory>
#include <vector>

namespace hystlab::models {

struct Grid {
  double lo = 0.0;  // δmin, mm
  double hi = 1.0;  // δmax, mm
  int n = 1;        // subdivisions
  // The nodes of a non-uniform grid (n + 1, strictly increasing, from lo to hi); empty: uniform.
  std::shared_ptr<const std::vector<double>> positions;

  // Throws std::invalid_argument naming the bad field.
  static Grid make(double lo, double hi, int n);
  // A grid with these nodes: at least 2, finite, strictly increasing. Nodes that are a uniform grid
  // (within 1e-12 of the range) give the uniform grid. Throws std::invalid_argument naming the node.
  static Grid from_nodes(const std::vector<double>& nodes);
  // n subdivisions of [lo, hi], `share` of them (rounded, at least 1) spread evenly over
  // [center - width/2, center + width/2] (clipped to the range) and the rest over the range outside
  // it, in proportion to its length on each side: refined around an operating point.
  static Grid refined(double lo, double hi, int n, double center, double width, double share = 0.5);

  [[nodiscard]] bool uniform() const noexcept { return !positions; }
  // The uniform spacing; for a non-uniform grid, its smallest cell.
  [[nodiscard]] double step() const noexcept;
  // Exact at both ends (i = 0 gives lo, i = n gives hi).
  [[nodiscard]] double node(int i) const noexcept {
    if (positions) return (*positions)[static_cast<std::size_t>(i)];
    return i == n ? hi : lo + (hi - lo) * static_cast<double>(i) / static_cast<double>(n);
  }
  // The cell i in 1..n holding x in [δ_{i-1}, δ_i] (x clamped to the grid), and x's place in it.
  [[nodiscard]] int cell_of(double x, double& fraction) const noexcept;
  // The same on a non-uniform grid's nodes[0..n], x in [nodes[0], nodes[n]]: the one binary
  // search of a refined grid, here so that the Everett table's step has it inline (out of line it
  // held the step at 0.79-0.93 of the bare loop's, bench_preisach) and cell_of calls it too.
  [[nodiscard, gnu::always_inline]] static int cell_among(const double* nodes, int n, double x, double& fraction) noexcept {
    const int k = static_cast<int>(std::upper_bound(nodes, nodes + n + 1, x) - nodes);
    const int i = k < 1 ? 1 : k > n ? n : k;
    fraction = (x - nodes[i - 1]) / (nodes[i] - nodes[i - 1]);
    return i;
  }
  [[nodiscard]] std::vector<double> nodes() const;
  // Lower-triangle node count (n+1)(n+2)/2 and the index of node (i, j), j <= i.
  [[nodiscard]] std::size_t node_count() const noexcept { return node_count(n); }
  [[nodiscard]] static std::size_t node_count(int n) noexcept {
    const auto m = static_cast<std::size_t>(n) + 1;
    return m * (m + 1) / 2;
  }
  [[nodiscard]] static std::size_t index(int i, int j) noexcept {
    const auto ii = static_cast<std::size_t>(i);
    return ii * (ii + 1) / 2 + static_cast<std::size_t>(j);
  }
  // Cells: (p, q) with 1 <= q <= p <= n; rectangle when q < p, triangle when q == p.
  [[nodiscard]] std::size_t cell_count() const noexcept {
    const auto m = static_cast<std::size_t>(n);
    return m * (m + 1) / 2;
  }
  [[nodiscard]] static std::size_t cell_index(int p, int q) noexcept { return index(p - 1, q - 1); }
  // Index i of the nearest node when x lies within tol of it, else -1.
  [[nodiscard]] int node_near(double x, double tol) const noexcept;
  // Same nodes (and so the same tables): for format checks and tests.
  [[nodiscard]] bool same_nodes(const Grid& other, double tol = 0.0) const noexcept;
};

}  // namespace hystlab::models
