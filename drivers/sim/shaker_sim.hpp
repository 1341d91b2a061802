#pragma once
// A virtual shaker: sine base excitation drives a mass on N SMA springs (the paper's Part II:
// a mass on layers of tubes). Fixed-step semi-implicit Euler; each spring's hysteretic force is
// updated once per step. Stable while dt·sqrt(N·k_max/m) << 2 (checked at construction).
// The controller's latches (Controller) stop the drive: zero amplitude, enable ignored.
//
// The base is not the drive. The table is a servo-driven mass (a displacement-controlled
// actuator: a second-order loop of natural frequency servo_hz and damping servo_damping) that
// carries the isolator, whose springs and damper push back on it. So the base amplitude per
// unit of drive depends on the frequency (about 1 well below servo_hz, up to 1/(2ζ) near it,
// falling beyond) and on the load (it dips where the isolator resonates and pulls hardest):
// what a real shaker does, and why sine controllers close the loop on the measured base.
// servo_hz = 0: an ideal table that follows the drive exactly.
#include <cstdint>
#include <memory>
#include <vector>

#include "controller.hpp"
#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::sim {

struct ShakerParams {
  // 13 kg on 4 springs of Table 1: 31.9 N each at a 0.80 mm preload on the austenite line
  // (KA = 40 N/mm), 0.21 mm below the forward transformation (Ms at 1.01 mm) and 0.80 mm from
  // lifting off; linearised natural frequency sqrt(4·40000/13)/2π = 17.7 Hz, damping ratio
  // 58/(2·sqrt(160000·13)) = 0.020. A base amplitude of 0.005 mm stays linear through the
  // resonance (relative motion ≈ 0.13 mm); 0.05 mm transforms the springs at resonance, and
  // their memory makes sweeping up and down differ (hystlab simulate sdof --sweep shows it too).
  double mass_kg = 13.0;
  int springs = 4;
  double damping_N_s_per_m = 58.0;  // structural damping beside the springs
  double k_max_N_per_mm = 150;      // stiffest line of the spring model, for the stability check
  double dt_s = 1e-4;
  double table_mass_kg = 20.0;  // the moving table (armature, fixture)
  double servo_hz = 60.0, servo_damping = 0.4;
  ControllerParams controller;  // mode interlock and host watchdog (default: neither)
};

struct ShakerCommands {
  double frequency_hz = 0, amplitude_mm = 0;
  bool enable = false, estop = false, fault_reset = false;
  std::uint16_t mode = 0;
  std::uint32_t host_heartbeat = 0;
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
  // The host's commands as last written (fault_reset acts on its rising edge).
  void set_commands(const ShakerCommands& c) noexcept;
  // Only the drive; the other commands stay as they were.
  void set_drive(double frequency_hz, double amplitude_mm, bool enable) noexcept;
  void step(double dt) noexcept;  // advances by dt in fixed internal steps
  void press_estop() noexcept;
  void latch_fault(std::uint16_t code) noexcept;
  [[nodiscard]] const Controller& controller() const noexcept { return ctl_; }
  [[nodiscard]] const ShakerState& state() const noexcept { return state_; }
  [[nodiscard]] double preload_mm() const noexcept { return preload_mm_; }

 private:
  void integrate_once() noexcept;
  void publish_status() noexcept;
  ShakerParams p_;
  ShakerCommands cmd_;
  Controller ctl_;
  std::vector<std::unique_ptr<models::HysteresisModel>> springs_;
  ShakerState state_;
  double phase_ = 0, carry_ = 0;
  double x_ = 0, v_ = 0, preload_mm_ = 0;  // mass displacement (m, from static equilibrium) and velocity
  double y_ = 0, yv_ = 0, weight_N_ = 0;   // the table's displacement (m) and velocity; the springs' static force
};

}  // namespace hystlab::sim
