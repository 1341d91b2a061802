#pragma once
// One measured point of a first-order-transition curve: rise to α (force f_α), fall to β (f_αβ).
#include <vector>

#include "hystlab/models/grid.hpp"
#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::models {

struct FotNode {
  double alpha = 0.0;             // mm
  double beta = 0.0;              // mm, <= alpha
  double force_alpha = 0.0;       // N
  double force_alpha_beta = 0.0;  // N
  [[nodiscard]] double everett() const noexcept { return force_alpha - force_alpha_beta; }
};

// The identification input of MODELS.md §1 as turning points: δmin, δ1, δmin, δ2, ..., δn, δmin.
[[nodiscard]] std::vector<double> fot_turning_points(const Grid& grid);

// Straight ramps through the turning points with at most max_step between samples.
[[nodiscard]] std::vector<double> ramp_through(const std::vector<double>& turning_points, double max_step);

struct VirtualCampaign {
  std::vector<FotNode> nodes;  // every (δ_i, δ_j), j <= i, in the order the campaign meets them
  double force_at_min = 0.0;   // the model's force when it first reaches δmin
};

// Runs the identification input on a model (from reset), stepping through every grid node.
[[nodiscard]] VirtualCampaign run_virtual_fot(HysteresisModel& model, const Grid& grid);

}  // namespace hystlab::models
