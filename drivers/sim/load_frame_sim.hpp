#pragma once
// A virtual servo-hydraulic load frame: the actuator command follows the setpoint at the ramp
// rate, the actuator follows the command with a first-order lag, the specimen (any hystlab
// model) gives the force, the load cell adds noise and drift. Hard limits, the e-stop and the
// host watchdog latch faults (Controller). Pure: time is passed in.
#include <cstdint>
#include <memory>
#include <random>

#include "controller.hpp"
#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::sim {

struct LoadFrameParams {
  double lag_s = 0.005;               // actuator time constant
  double max_rate_mm_s = 500;         // the valve's limit, whatever the ramp rate asks
  double limit_mm = 12.0;             // hard displacement limits ±limit_mm
  double load_cell_range_N = 5000;    // beyond it the load cell trips the frame
  double noise_N = 0.05;              // load cell noise, 1 σ
  double drift_N_per_s = 0.0;         // slow load cell drift
  double corner_width_mm = 0.05;      // corner smoothing of the specimen (0: none)
  double deadband_mm = 0;             // the servo stops correcting when |command - displacement| < this
  double recovery_rate_mm_s = 1.0;    // limit recovery: the fastest the frame moves back into its stroke
  double overtravel_rate_mm_s = 5.0;  // the outside push of `fault overtravel` (a hand set's jog)
  std::uint64_t seed = 1;
  ControllerParams controller;  // mode interlock and host watchdog (default: neither)
};

// The specimen's force with its corners rounded, in displacement (not in time, so the loop keeps
// its rate independence), like the measured tube (paper Fig. 3): the force follows the sharp
// model's slope through a first-order filter, k_s += (k - k_s)(1 - exp(-|Δδ|/w)), f_s += k_s Δδ,
// and is pulled back to the sharp force over 4w. A straight line is followed exactly once k_s has
// settled, and a reversal takes the new slope at once (elastic unloading is sharp in a real
// spring). Filtering the force itself instead (until stop 23) lagged it by slope × w on every
// straight part, in opposite directions on loading and unloading: an elastic loop on the
// austenite line dissipated -3 N·mm, a spring giving energy back, which no material does.
class SmoothedSpecimen {
 public:
  SmoothedSpecimen(std::unique_ptr<models::HysteresisModel> model, double width_mm);
  double step(double displacement_mm) noexcept;

 private:
  std::unique_ptr<models::HysteresisModel> model_;
  double width_, x_ = 0, f_ = 0;
  double sharp_ = 0, slope_ = 0;  // the sharp model's last force, and the filtered slope
  int dir_ = 0;                   // the input's last direction of motion
};

struct LoadFrameCommands {
  double setpoint_mm = 0, ramp_rate_mm_s = 1;
  bool enable = false, hold = false, estop = false;
  bool fault_reset = false;
  std::uint16_t mode = 0;
  std::uint32_t host_heartbeat = 0;
};

struct LoadFrameState {
  double time_s = 0, command_mm = 0, displacement_mm = 0, force_N = 0;
  std::uint16_t status_word = 0, fault_code = 0;
  std::uint32_t heartbeat = 0, sample_counter = 0;
};

class LoadFrameSim {
 public:
  LoadFrameSim(std::unique_ptr<models::HysteresisModel> specimen, LoadFrameParams params);
  // The host's commands as last written (fault_reset acts on its rising edge).
  void set_commands(const LoadFrameCommands& c) noexcept;
  // Advances by dt (simulated seconds) and takes one sample.
  void step(double dt) noexcept;
  [[nodiscard]] const LoadFrameState& state() const noexcept { return state_; }
  // The operator: the e-stop button, a latched fault with its code, the servo's dead band.
  void press_estop() noexcept;
  void latch_fault(std::uint16_t code) noexcept;
  void set_deadband(double mm) noexcept { p_.deadband_mm = mm; }
  // An outside cause (the hand set's jog, a specimen giving way) pushes the actuator toward mm
  // whatever the host commands, until it gets there or the controller latches (a limit trip).
  void overtravel(double mm) noexcept { overtravel_ = true, overtravel_to_ = mm; }
  [[nodiscard]] double deadband() const noexcept { return p_.deadband_mm; }
  [[nodiscard]] const Controller& controller() const noexcept { return ctl_; }

 private:
  [[nodiscard]] bool limit_cause_present() const noexcept;
  void check_limits() noexcept;
  void advance_command(double dt) noexcept;
  void publish_status(bool driving) noexcept;
  LoadFrameParams p_;
  SmoothedSpecimen specimen_;
  LoadFrameCommands cmd_;
  LoadFrameState state_;
  Controller ctl_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> noise_{0.0, 1.0};
  bool overtravel_ = false;
  double overtravel_to_ = 0;
  double recovery_closest_ = 0;  // limit recovery: the least |displacement| since it began
};

}  // namespace hystlab::sim
