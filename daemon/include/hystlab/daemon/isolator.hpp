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
//            7 (a table in this daemon's store, by id: a sine plan's "isolator" only), or
//   "linear_N_per_mm": 40}
// A simulated shaker without one is predicted with the simulator's own isolator. A sine plan's
// own "isolator" (the same fields) replaces the rig's for that campaign.
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <stdexcept>
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
// What is wrong with an isolator, naming the field ("rigs[1].isolator.table names a file ...").
struct IsolatorError : std::invalid_argument {
  IsolatorError(std::string field_name, const std::string& what) : std::invalid_argument(what), field(std::move(field_name)) {}
  std::string field;
};
// A stored table's document by id (db::Reads::table_document), none when there is no such table.
using TableLookup = std::function<std::optional<std::string>(std::int64_t)>;
// A rig config's or a plan's "isolator" (where: "rigs[1].isolator", "isolator"); throws
// IsolatorError. `stored` (a plan's) resolves "table": ID, and refuses a file path (a plan comes
// over the network); without it an id is refused. Mass, springs and damping not given are
// base's (the rig's isolator, for a plan's), else the simulator's.
[[nodiscard]] IsolatorModel parse_isolator(const nlohmann::json& j, const std::string& where, const TableLookup& stored = {},
                                           const IsolatorModel* base = nullptr);

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
