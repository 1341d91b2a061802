#pragma once
// The isolator of the paper's Part II: a mass on N springs over a base moved sinusoidally.
// Units: mm, N, kg, s (acceleration in mm/s² is 1000·F/m). Up is positive for the base (y) and
// the mass (x); the springs' compression is δ = preload + y − x, and they only push (a spring
// that would be in tension has lifted off: force 0, counted).
//
// Fixed-step velocity Verlet, the linear damper taken implicitly. The hysteretic force is
// evaluated once per step at the new position, so each spring's memory is updated exactly once
// per accepted step. Energies are integrated alongside (trapezoids), in N·mm.
#include <cstdint>
#include <memory>
#include <vector>

#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::models {

class PreisachModel;

struct SdofSpring {
  std::unique_ptr<HysteresisModel> model;
  double max_stiffness_N_per_mm = 0;  // an upper bound of the tangent stiffness (stability)
};

struct SdofOptions {
  double mass_kg = 1.0;
  double damping_N_s_per_mm = 0.0;  // a linear damper beside the springs
  double preload_mm = 0.0;          // static compression under the weight (the weight balances it)
  double dt_s = 1e-4;
};

struct SdofEnergy {    // N·mm, since the start
  double input = 0;    // work done by the base on the springs and the damper
  double spring = 0;   // work done on the springs (stored + dissipated by hysteresis)
  double damper = 0;   // dissipated by the damper
  double kinetic = 0;  // of the mass, now
  double gravity = 0;  // weight × rise of the mass, now
  [[nodiscard]] double residual() const noexcept { return input - spring - damper - kinetic - gravity; }
};

struct SdofState {
  double t = 0, y = 0, y_dot = 0, x = 0, v = 0, a = 0, delta = 0, force = 0;
};

class SdofSystem {
 public:
  // Loads the springs quasi-statically to the preload; the weight is what they then carry.
  // Throws std::invalid_argument naming the problem (no spring, mass, damping, or a step that
  // would be unstable: dt·ω_max must stay below 1, ω_max = sqrt(1000·Σk_max/m)).
  SdofSystem(std::vector<SdofSpring> springs, const SdofOptions& options);

  // The base: y = Y sin φ with φ advancing at 2πf; changing f keeps the motion continuous.
  void set_base(double amplitude_mm, double frequency_hz) noexcept;
  void step() noexcept;
  void run_for(double seconds) noexcept;

  [[nodiscard]] const SdofState& state() const noexcept { return s_; }
  [[nodiscard]] const SdofEnergy& energy() const noexcept { return e_; }
  [[nodiscard]] double weight_N() const noexcept { return weight_; }
  [[nodiscard]] double omega_max() const noexcept { return omega_max_; }
  [[nodiscard]] std::uint64_t lift_off_steps() const noexcept { return lift_off_; }
  [[nodiscard]] double dt() const noexcept { return opt_.dt_s; }

 private:
  double spring_force(double delta) noexcept;
  void group_tables();

  std::vector<SdofSpring> springs_;
  // When every spring is a table, the integrator calls the tables' step directly (inlined: the
  // interface's virtual call kept an isolator of two n = 12 tables at 0.63 of linear springs,
  // issue 27), and springs of one table and options are one model evaluated once and counted:
  // in parallel from one reset, they see the same δ at every step, so their memories are equal
  // (the sum equal to rounding). The group's other models stay at their reset: nothing reads
  // a spring's own state (add an accessor only with that in mind).
  struct TableGroup {
    PreisachModel* model;
    double count;
  };
  std::vector<TableGroup> tables_;  // empty: the springs are called through HysteresisModel
  SdofOptions opt_;
  SdofState s_;
  SdofEnergy e_;
  double weight_ = 0, omega_max_ = 0, amplitude_ = 0, omega_ = 0, phase_ = 0;
  std::uint64_t lift_off_ = 0;
};

// Steady response at one frequency, continuing from the system's state: settle_cycles, then
// measured_cycles fitted by least squares at the base frequency.
struct SteadyResponse {
  double frequency_hz = 0, base_amplitude_mm = 0, mass_amplitude_mm = 0, ratio = 0, phase_rad = 0;
  double peak_to_peak_ratio = 0;  // (max − min of x) / (max − min of y): what a non-sinusoidal response does
};
[[nodiscard]] SteadyResponse steady_response(SdofSystem& system, double amplitude_mm, double frequency_hz, int settle_cycles, int measured_cycles);

// |X/Y| of a linear mass-spring-damper under base excitation, at frequency ratio r and damping ratio ζ.
[[nodiscard]] double linear_transmissibility(double r, double zeta) noexcept;

// Upper bound of a table's tangent stiffness: the largest slope between neighbouring nodes.
class EverettTable;
[[nodiscard]] double max_stiffness(const EverettTable& table) noexcept;

}  // namespace hystlab::models
