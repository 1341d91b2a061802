#pragma once
// The isolator a shaker carries, as a model the daemon can simulate (models::SdofSystem): its
// mass, its springs (each a copy of one spring model), the damper beside them. With one, a sine
// campaign stores the predicted transmissibility beside each measured point, at the measured
// base amplitude and the step's frequency, carrying the springs' memory from step to step in the
// order the rig took them.
//
// Rig config: "isolator": {"mass_kg": 13, "springs": 4, "damping_N_s_per_m": 58, and its springs
//   "params": {...simplified-model parameters...}   (Table 1 when no spring is given), or
//   "table": "S-07.json" or {...a table document...} (a Preisach table identified on a load frame:
//            the mission's chain, identify the springs on the frame, predict the isolator), or
//   "linear_N_per_mm": 40}
// A simulated shaker without one is predicted with the simulator's own isolator.
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::daemon {

struct IsolatorModel {
  double mass_kg = 13.0, damping_N_s_per_m = 58.0;
  int springs = 4;
  std::shared_ptr<const models::HysteresisModel> spring;  // compression (mm) -> force (N), one spring
  double max_stiffness_N_per_mm = 150;                    // of one spring (the integrator's stability)
  std::string describe;                                   // for the record: "13 kg on 4 springs (simplified model, ...)"
};

// The simulator's default isolator (drivers/sim/shaker_sim.hpp: 13 kg, 4 springs of Table 1, 58 N·s/m).
[[nodiscard]] IsolatorModel simulated_isolator();
// A rig config's "isolator"; throws std::invalid_argument naming the field (where: "rigs[1].isolator").
[[nodiscard]] IsolatorModel parse_isolator(const nlohmann::json& j, const std::string& where);

struct PredictStep {
  double frequency_hz = 0, base_amplitude_mm = 0;
  int settle_cycles = 0;  // what the rig gave the step before measuring (the prediction gives at least 30 cycles and 3 s)
  int measured_cycles = 10;
};
struct Predicted {
  double ratio = 0, phase_rad = 0;
};
// The steady response at each step in turn, from the isolator at rest on its preload.
[[nodiscard]] std::vector<Predicted> predict_sweep(const IsolatorModel& iso, std::span<const PredictStep> steps);

}  // namespace hystlab::daemon
