#pragma once
// The FOT grid: n equal subdivisions of [lo, hi] (MODELS.md §1).
#include <cstddef>

namespace hystlab::models {

struct Grid {
  double lo = 0.0;  // δmin, mm
  double hi = 1.0;  // δmax, mm
  int n = 1;        // subdivisions

  // Throws std::invalid_argument naming the bad field.
  static Grid make(double lo, double hi, int n);

  [[nodiscard]] double step() const noexcept { return (hi - lo) / n; }
  // Exact at both ends (i = 0 gives lo, i = n gives hi).
  [[nodiscard]] double node(int i) const noexcept {
    return i == n ? hi : lo + (hi - lo) * static_cast<double>(i) / static_cast<double>(n);
  }
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
};

}  // namespace hystlab::models
