#pragma once
// The FOT (Everett) function F(α,β) on a grid, read by the paper's rectangle/triangle
// interpolation (Eqs. 8 and 9). Values are F(δ_i, δ_j) for 0 <= j <= i <= n.
#include <algorithm>
#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "hystlab/models/grid.hpp"

namespace hystlab::models {

// Up to four node indices and weights whose weighted sum is F at a point.
struct InterpolationStencil {
  std::array<std::size_t, 4> node{};
  std::array<double, 4> weight{};
  int size = 0;
};

class EverettTable {
 public:
  EverettTable() : EverettTable(Grid{}) {}
  // All nodes zero.
  explicit EverettTable(Grid grid);
  // Throws std::invalid_argument when values has the wrong size, holds a non-finite value,
  // or a diagonal value F(δ_i, δ_i) is not zero.
  EverettTable(Grid grid, std::vector<double> values, double force_offset = 0.0);

  [[nodiscard]] const Grid& grid() const noexcept { return grid_; }
  [[nodiscard]] std::span<const double> values() const noexcept { return values_; }
  [[nodiscard]] double node_value(int i, int j) const noexcept { return values_[Grid::index(i, j)]; }
  // Force at δmin added to the Preisach sum (zero when identified from rest at δmin).
  [[nodiscard]] double force_offset() const noexcept { return force_offset_; }

  // F(a, b) with a, b clamped to the grid and b clamped to <= a. Continuous.
  [[nodiscard]] double value(double a, double b) const noexcept {
    const double lo = grid_.lo, hi = grid_.hi;
    a = a < lo ? lo : (a > hi ? hi : a);
    b = b < lo ? lo : (b > a ? a : b);
    return value_in_range(a, b);
  }

  // F(a, b) for lo <= b <= a <= hi (the memory stack guarantees it): no clamping. Always inlined:
  // it is the Preisach step's one lookup, and GCC 12 at -O2 kept it out of line (bench_preisach:
  // the step at 0.65 of the bare loop with it and the step called, issue 27).
  [[nodiscard, gnu::always_inline]] double value_in_range(double a, double b) const noexcept {
    int i = 0, j = 0;
    double s = 0.0, t = 0.0;
    cell_of(a, b, i, j, s, t);
    const double* r1 = values_.data() + Grid::index(i - 1, 0);
    const double* r2 = values_.data() + Grid::index(i, 0);
    if (j < i) {  // rectangle, Eq. 8: bilinear in the four corners
      const double f00 = r1[j - 1], f01 = r1[j], f10 = r2[j - 1], f11 = r2[j];
      return (1.0 - s) * ((1.0 - t) * f00 + t * f01) + s * ((1.0 - t) * f10 + t * f11);
    }
    // triangle on the diagonal, Eq. 9: linear through (δ_{i-1},δ_{i-1}), (δ_i,δ_{i-1}), (δ_i,δ_i)
    const double f1 = r1[i - 1], f2 = r2[i - 1], f3 = r2[i];
    return f1 + (f2 - f1) * s + (f3 - f2) * (t < s ? t : s);
  }

  // The same interpolation as value(), as weights on nodes (for linear identification).
  [[nodiscard]] InterpolationStencil stencil(double a, double b) const noexcept;

 private:
  // Cell of (a, b), lo <= b <= a <= hi: column i with a in [δ_{i-1}, δ_i], row j <= i with b in
  // [δ_{j-1}, δ_j], and the local coordinates s, t in [0, 1] (t <= s in a triangle).
  [[gnu::always_inline]] void cell_of(double a, double b, int& i, int& j, double& s, double& t) const noexcept {
    if (nodes_) {  // a grid of its own: the cells by binary search, s and t in each cell's own width
      i = Grid::cell_among(nodes_, grid_.n, a, s);
      j = Grid::cell_among(nodes_, grid_.n, b, t);
      if (j > i) j = i, t = s;
      return;
    }
    // floor + 1: a point on a node line may be read from either neighbouring cell, where both
    // interpolations agree (F is continuous), so the cheaper floor is as good as a ceiling.
    const double u = (a - grid_.lo) * inv_step_, w = (b - grid_.lo) * inv_step_;
    i = static_cast<int>(u) + 1;
    i = i > grid_.n ? grid_.n : i;
    j = static_cast<int>(w) + 1;
    j = j > i ? i : j;
    s = u - static_cast<double>(i - 1);
    t = w - static_cast<double>(j - 1);
  }

  Grid grid_;
  double inv_step_ = 1.0;
  const double* nodes_ = nullptr;  // a non-uniform grid's nodes (grid_.positions, shared: valid while grid_ is)
  std::vector<double> values_;
  double force_offset_ = 0.0;
};

}  // namespace hystlab::models
