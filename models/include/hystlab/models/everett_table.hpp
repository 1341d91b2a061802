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

// The cell a branch of the Preisach step reads (PreisachModel::advance). Along a branch one of F's
// arguments is the branch's turning point and stays; only the input moves, a little a step when
// it is a smooth signal (an isolator's spring: tens to hundreds of steps a cell, 40 % of them in
// the diagonal's triangle when the spring's stroke is within a cell). While the input stays in
// one cell, F is the same arithmetic on the same numbers, so the step keeps them and computes only
// the input's weight: no cell search, no index, no loads (bench_sdof, issue 27: an isolator of
// two different tables from 0.67 to 0.84 of linear springs with it and the step inlined). The same
// operations in the same order as value_in_range, on the same numbers: bit-identical to it.
struct BranchCell {
  enum class Kind : unsigned char { rectangle, triangle };
  Kind kind = Kind::rectangle;
  bool rising = false;          // the input is F's first argument (rising from a minimum), else its second
  double from = 0.0, to = 0.0;  // the input's cell, [from, to) in u = (x − lo)·(1/h) as cell_of computes it (uniform) or in x; empty at first
  // Rectangle: a, b, c, d the corners f00, f01, f10, f11, g0 and g1 F along the cell's two
  // column edges at the turning point's t; rising F = (1−s)·g0 + s·g1, falling
  // F = (1−s)·((1−t)·a + t·b) + s·((1−t)·c + t·d). Triangle: a = f1, b = f2 − f1, c = f3 − f2,
  // d = a + b·s; rising F = a + b·s + c·min(t, s), falling F = d + c·min(t, s). Both directions'
  // numbers are kept, so that keeping them has no branch on the direction (random inputs).
  double a = 0.0, b = 0.0, c = 0.0, d = 0.0, g0 = 0.0, g1 = 0.0, s = 0.0, t = 0.0;
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
    BranchCell unused;
    return read<false>(a, b, false, unused);
  }

  // F on a branch: rising from a minimum m, F(x, m); falling from a maximum M, F(M, x).
  // coordinate: x where cells are found (uniform: u, as cell_of computes it; refined: x itself);
  // in_cell: that is in the cell kept for this direction; cell_value: F there. branch_value reads
  // F anew and keeps x's cell. The weight comes from the one rounded coordinate the cell test
  // compared, as cell_of's comes from its rounded u (converted to an int there): so where a
  // compiler fuses a·b + c into one FMA (GCC's default on aarch64), the two paths still round
  // alike, their other expressions being the same ones.
  [[nodiscard, gnu::always_inline]] double coordinate(double x) const noexcept { return nodes_ ? x : (x - grid_.lo) * inv_step_; }
  [[nodiscard, gnu::always_inline]] static bool in_cell(const BranchCell& c, bool rising, double v) noexcept {
    return v >= c.from && v < c.to && c.rising == rising;
  }
  [[nodiscard, gnu::always_inline]] double cell_value(const BranchCell& c, double v) const noexcept {
    // x's weight in its cell (s rising, t falling), as cell_of computes it: uniform, from is
    // floor(u) and the difference exact; refined, as Grid::cell_among.
    const double w = nodes_ ? (v - c.from) / (c.to - c.from) : v - c.from;
    if (c.kind == BranchCell::Kind::rectangle) {
      if (c.rising) return (1.0 - w) * c.g0 + w * c.g1;
      return (1.0 - c.s) * ((1.0 - w) * c.a + w * c.b) + c.s * ((1.0 - w) * c.c + w * c.d);
    }
    if (c.rising) return c.a + c.b * w + c.c * (c.t < w ? c.t : w);
    return c.d + c.c * (w < c.s ? w : c.s);
  }
  [[nodiscard, gnu::always_inline]] double branch_value(double a, double b, bool rising, BranchCell& keep) const noexcept {
    return read<true>(a, b, rising, keep);
  }

  // This table's values and offset become (1 - w)·a + w·b (a and b on this table's grid; the
  // thermal model's blend, which allocates nothing). Throws std::invalid_argument when a or b has
  // another number of nodes.
  void assign_blend(const EverettTable& a, const EverettTable& b, double w);

  // The same interpolation as value(), as weights on nodes (for linear identification).
  [[nodiscard]] InterpolationStencil stencil(double a, double b) const noexcept;

 private:
  template <bool kKeep>
  [[gnu::always_inline]] double read(double a, double b, bool rising, BranchCell& keep) const noexcept {
    int i = 0, j = 0;
    double s = 0.0, t = 0.0;
    cell_of(a, b, i, j, s, t);
    const double* r1 = values_.data() + Grid::index(i - 1, 0);
    const double* r2 = values_.data() + Grid::index(i, 0);
    if constexpr (kKeep) {  // the input's cell: its column rising, its row falling
      const int k = rising ? i : j;
      keep.from = nodes_ ? nodes_[k - 1] : static_cast<double>(k - 1);
      keep.to = nodes_ ? nodes_[k] : static_cast<double>(k);
      keep.rising = rising;
    }
    using K = BranchCell::Kind;
    if (j < i) {  // rectangle, Eq. 8: bilinear in the four corners
      const double f00 = r1[j - 1], f01 = r1[j], f10 = r2[j - 1], f11 = r2[j];
      const double g0 = (1.0 - t) * f00 + t * f01, g1 = (1.0 - t) * f10 + t * f11;
      if constexpr (kKeep) keep.kind = K::rectangle, keep.a = f00, keep.b = f01, keep.c = f10, keep.d = f11, keep.g0 = g0, keep.g1 = g1, keep.s = s, keep.t = t;
      return (1.0 - s) * g0 + s * g1;
    }
    // triangle on the diagonal, Eq. 9: linear through (δ_{i-1},δ_{i-1}), (δ_i,δ_{i-1}), (δ_i,δ_i)
    const double f1 = r1[i - 1], f2 = r2[i - 1], f3 = r2[i];
    const double along = f1 + (f2 - f1) * s;
    if constexpr (kKeep) keep.kind = K::triangle, keep.a = f1, keep.b = f2 - f1, keep.c = f3 - f2, keep.d = along, keep.s = s, keep.t = t;
    return along + (f3 - f2) * (t < s ? t : s);
  }

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
