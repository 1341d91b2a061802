#pragma once
// Preisach identification from any displacement/force record by regularised least squares, with
// the model class as a choice decided by data (issue 13).
//
// Unknowns: the mass w_c of every grid cell and a force offset; the table is
// F(δ_i, δ_j) = Σ of the masses of the cells in the triangle β >= δ_j, α <= δ_i, so F(α,α) = 0.
// The priors:
//  - monotone: w_c >= 0, the classical Preisach measure (F monotone; what `fit` did before);
//  - signed: w_c of any sign. The superelastic specimen needs it: its martensite is stiffer than
//    its austenite, and elastic unloading lines whose slope depends on the history cannot come
//    from positive relays alone (the simplified model's own FOT table has 14 of 78 negative cells
//    at n = 12);
//  - automatic: both, and the one with the lower error on held-out data wins.
// Both are smoothed by λ |D w|² (first differences between neighbouring cells), λ chosen by
// cross-validation on contiguous held-out blocks of the record: a block's memory state comes from
// the whole record before it, so its error is the error a user would see on new data.
//
// Scale: the normal equations are applied, never formed (PreisachOperator), and solved by
// preconditioned conjugate gradients (signed) or gradient projection with conjugate gradients on
// the free face (monotone), so memory is O(samples + cells) and n = 200 fits (20,100 cells).
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hystlab/models/everett_table.hpp"

namespace hystlab::models {

enum class FitPrior { signed_masses, monotone, automatic };
[[nodiscard]] std::string_view to_string(FitPrior p) noexcept;
// "signed", "monotone", "auto"; throws std::invalid_argument naming the accepted words.
[[nodiscard]] FitPrior fit_prior_from_string(std::string_view s);

struct PreisachFitOptions {
  FitPrior prior = FitPrior::automatic;
  double lambda = -1.0;        // smoothing weight (relative: data and smoothing both scaled to unit trace); < 0: by CV
  int folds = 4;               // contiguous held-out blocks for the cross-validation
  int uncertainty_probes = 8;  // random probes for the per-cell σ (0: none)
  double tolerance = 1e-7;     // relative residual of the final solve
  int max_subdivisions = 200;
};

// One prior's result.
struct PriorFit {
  FitPrior prior = FitPrior::signed_masses;
  EverettTable table;
  double lambda = 0.0;
  double heldout_rms = 0.0;       // N, cross-validated error at the chosen (or given) λ
  std::vector<double> cv_lambda;  // the λ tried, and their held-out RMS (N)
  std::vector<double> cv_rms;
  double rms_residual = 0.0;        // N, on the whole record, by running the fitted table
  double max_residual = 0.0;        // N
  double force_offset = 0.0;        // N
  std::vector<double> cell_weight;  // N, Grid::cell_index order
  std::vector<double> cell_sigma;   // N, 1-σ, estimated from random probes; 0 at the bound w = 0
  std::size_t cells_at_bound = 0;
  std::size_t negative_cells = 0;
  int iterations = 0;     // conjugate-gradient steps of all its solves
  bool converged = true;  // the final solve met its tolerance (else the reason warns)
};

struct PreisachFitResult {
  PriorFit chosen;
  std::vector<PriorFit> candidates;  // every prior fitted (two for automatic), chosen among them
  std::string reason;                // why `chosen` won, in the user's words
  double seconds = 0.0;
  std::size_t operator_bytes = 0;  // the record's operator: the largest allocation of the fit
  std::size_t selection_samples = 0;
  std::size_t peak_bytes = 0;  // operator + solver vectors, estimated from their sizes
  // Samples λ and the prior were chosen on: all of them, or above 200,000 the record thinned to
  // about that many with every turning point kept (the chosen prior is then fitted on every
  // sample; the other candidate's figures are from the thinned record, σ scaled from it).
};

// Throws std::invalid_argument on mismatched sizes, non-finite data, too few samples for the
// unknowns, n above options.max_subdivisions, or fewer than 2 folds; messages name the field.
[[nodiscard]] PreisachFitResult fit_preisach(std::span<const double> input, std::span<const double> force, const Grid& grid,
                                             const PreisachFitOptions& options = {});

}  // namespace hystlab::models
