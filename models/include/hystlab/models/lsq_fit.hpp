#pragma once
// Preisach identification from arbitrary data (not only FOT paths), by constrained least squares.
//
// Unknowns: the Preisach mass w_c >= 0 of every grid cell and a free force offset. The table is
// F(δ_i, δ_j) = Σ of the masses of the cells inside the triangle β >= δ_j, α <= δ_i, so F is
// monotone and F(α,α) = 0 by construction. The model output is linear in F (the memory stack
// and the interpolation are), hence in w. A first-difference smoothing term λ|Dw|² is added;
// λ is chosen by generalized cross-validation on the unconstrained problem, then the
// non-negative problem is solved by an active-set method.
#include <cstddef>
#include <span>
#include <vector>

#include "hystlab/models/everett_table.hpp"

namespace hystlab::models {

struct LsqFitOptions {
  double lambda = -1.0;  // smoothing weight; < 0 chooses it by GCV
  int gcv_points = 41;   // λ values tried (log-spaced)
};

struct LsqFitResult {
  EverettTable table;
  double lambda = 0.0;  // relative to the data term (both scaled to unit trace)
  double gcv = 0.0;
  double effective_parameters = 0.0;
  double rms_residual = 0.0;        // N
  double max_residual = 0.0;        // N
  double force_offset = 0.0;        // N
  std::vector<double> cell_weight;  // N, Grid::cell_index order
  std::vector<double> cell_sigma;   // N, 1-σ uncertainty; 0 for cells held at the bound w = 0
  std::size_t cells_at_bound = 0;
  int active_set_iterations = 0;
};

// The linear map from table values to the model output: out[k] = Σ_node row_k[node] F_node.
// Calls sink(k, stencil terms) for each sample; used by the fit and checked against PreisachModel.
struct RegressorTerm {
  std::size_t node;
  double weight;
};
[[nodiscard]] std::vector<std::vector<RegressorTerm>> preisach_regressors(const Grid& grid, std::span<const double> input);

// Throws std::invalid_argument on mismatched sizes, non-finite data, too few samples, or n > 64.
[[nodiscard]] LsqFitResult fit_preisach_lsq(std::span<const double> input, std::span<const double> force, const Grid& grid, const LsqFitOptions& options = {});

}  // namespace hystlab::models
