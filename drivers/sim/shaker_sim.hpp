#pragma once
// A virtual shaker: sine base excitation drives a mass on N SMA springs (the paper's Part II:
// a mass on layers of tubes). Fixed-step semi-implicit Euler; each spring's hysteretic force is
// updated once per step. Stable while dt·sqrt(N·k_max/m) << 2 (checked at construction).
#include <cstdint>
#include <memory>
#include <vector>

#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::sim {

struct ShakerParams {
  double mass_kg = 0.5;
  int springs = 4;
  double damping_N_s_per_m = 2.0;  // a little structural damping
  double k_max_N_per_mm = 150;     // stiffest line of the spring model, for the stability check
  double dt_s = 1e-4;
};

struct ShakerState {
  double time_s = 0, base_accel_m_s2 = 0, mass_accel_m_s2 = 0, base_displacement_mm = 0, mass_displacement_mm = 0;
  std::uint16_t status_word = 0, fault_code = 0;
  std::uint32_t heartbeat = 0, sample_counter = 0;
};

class ShakerSim {
 public:
  // spring: prototype of one spring's model (compression in mm -> force in N); cloned N times.
  ShakerSim(const models::HysteresisModel& spring, ShakerParams params);  // throws if unstable
  void set_drive(double frequency_hz, double amplitude_mm, bool enable) noexcept;
  void step(double dt) noexcept;  // advances by dt in fixed internal steps
  [[nodiscard]] const ShakerState& state() const noexcept { return state_; }
  [[nodiscard]] double preload_mm() const noexcept { return preload_mm_; }

 private:
  void integrate_once() noexcept;
  ShakerParams p_;
  std::vector<std::unique_ptr<models::HysteresisModel>> springs_;
  ShakerState state_;
  double frequency_ = 0, amplitude_m_ = 0, phase_ = 0, carry_ = 0;
  bool enable_ = false;
  double x_ = 0, v_ = 0, preload_mm_ = 0;  // mass displacement (m, from static equilibrium) and velocity
};

}  // namespace hystlab::sim
