#pragma once
// The figures a materials lab reports for every closed cycle of a force-displacement record:
// peak force, dissipated energy (the loop's area), secant stiffness, equivalent viscous damping,
// plateau forces at set displacements (ASTM F2516 reports the stress at fixed strains on loading
// and unloading; here force at displacement, for springs), transformation points by tangent
// intersection, and the force at return to the cycle's minimum.
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "hystlab/models/branch_knees.hpp"
#include "hystlab/models/simplified_sma.hpp"

namespace hystlab::models {

struct LoopOptions {
  std::vector<double> plateau_at_mm;  // displacements where loading and unloading forces are read
  // A reversal counts when the input turns back by more than this fraction of the record's
  // displacement range (noise on the displacement makes no cycles).
  double reversal_fraction = 0.01;
  // Cycles spanning less than this fraction of the record's range are not reported.
  double min_span_fraction = 0.02;
};

struct PlateauForce {
  double at_mm = 0, loading_N = 0, unloading_N = 0;
};

struct LoopFigures {
  // Samples of the record: the start, the turn and the return to the start's displacement. A cycle
  // starts at a minimum (up, then back down) or, inside a loading, at a maximum (down, back up).
  std::size_t begin = 0, turn = 0, end = 0;
  bool starts_at_max = false;
  double min_mm = 0, max_mm = 0;
  double force_at_min_N = 0, force_at_max_N = 0;
  double peak_force_N = 0;  // the largest force in the cycle
  double return_N = 0;      // the force back at the start's displacement (at δmin for a cycle from a minimum)
  // A cycle from a minimum: how far from the start the unloading branch is when its force is back
  // down to the start's (within 1 % of the cycle's force range); 0 when it gets there only at the
  // start. ASTM F2516's residual elongation after unloading, in displacement for a spring. NaN for
  // a cycle from a maximum (it does not unload to a start).
  double residual_mm = 0;
  double energy_Nmm = 0;               // ∮ f dδ, the energy dissipated in the cycle
  double secant_stiffness_N_mm = 0;    // (f(max) - f(min)) / (max - min)
  double strain_energy_Nmm = 0;        // E_s = ½ k a², a = (max - min) / 2 (the loop about its centre)
  double damping_ratio = 0;            // ζ = E_d / (4π E_s); 0 when E_s is 0
  std::vector<PlateauForce> plateaus;  // those of the options inside [min, max]
  std::optional<BranchKnees> loading, unloading;
  // Ms, Mf (loading) and As, Af (unloading) when both branches show a plateau.
  std::optional<SmaTransitions> transformation;
};

// Every closed cycle of a record, by rainflow counting of its reversals (ASTM E1049): a cycle goes
// from a turning point to the next and back to the first's displacement (within the reversal
// band). A cycle nested in another is reported once, and its samples are left out of its host's
// figures. Cycles closed only by the record's end count when they return to their minimum.
// Reported in the order they close. Sizes must match and be finite (std::invalid_argument otherwise).
[[nodiscard]] std::vector<LoopFigures> find_loops(std::span<const double> displacement, std::span<const double> force, const LoopOptions& options = {});

// The figures of one cycle of samples begin..end, turning at `turn` (begin < turn < end).
[[nodiscard]] LoopFigures loop_figures(std::span<const double> displacement, std::span<const double> force, std::size_t begin, std::size_t turn,
                                       std::size_t end, const LoopOptions& options = {});

// Transformation points of one loop (loading up to its largest displacement, unloading after it),
// or nullopt when a branch shows no plateau. The starting guess of calibrate_simplified_sma.
[[nodiscard]] std::optional<SmaTransitions> loop_transformation(std::span<const double> displacement, std::span<const double> force);

}  // namespace hystlab::models
