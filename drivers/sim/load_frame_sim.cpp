#include "load_frame_sim.hpp"

#include <algorithm>
#include <cmath>

#include "hystlab/protocols/signals.hpp"

namespace hystlab::sim {
namespace st = protocols::status;

SmoothedSpecimen::SmoothedSpecimen(std::unique_ptr<models::HysteresisModel> model, double width_mm)
    : model_(std::move(model)), width_(width_mm) {
  x_ = model_->input();
  f_ = model_->output();
}

double SmoothedSpecimen::step(double x) noexcept {
  const double f = model_->step(x);
  const double dx = std::fabs(x - x_);
  x_ = x;
  f_ = width_ > 0 ? f_ + (f - f_) * (1.0 - std::exp(-dx / width_)) : f;
  return f_;
}

LoadFrameSim::LoadFrameSim(std::unique_ptr<models::HysteresisModel> specimen, LoadFrameParams params)
    : p_(params), specimen_(std::move(specimen), params.corner_width_mm), rng_(params.seed) {
  state_.status_word = st::ready;
}

void LoadFrameSim::set_commands(const LoadFrameCommands& c) noexcept {
  cmd_ = c;
  if (c.estop && !tripped_) {
    tripped_ = true;
    state_.fault_code = kEstopPressed;
  }
}

void LoadFrameSim::reset_fault() noexcept {
  if (cmd_.estop) return;
  tripped_ = false;
  state_.fault_code = kNoFault;
}

void LoadFrameSim::step(double dt) noexcept {
  LoadFrameState& s = state_;
  s.time_s += dt;
  const bool driving = cmd_.enable && !cmd_.hold && !tripped_;
  if (driving) {  // command moves toward the setpoint at the ramp rate (and never faster than the valve)
    const double rate = std::min(std::fabs(cmd_.ramp_rate_mm_s), p_.max_rate_mm_s);
    const double step = std::clamp(cmd_.setpoint_mm - s.command_mm, -rate * dt, rate * dt);
    s.command_mm += step;
  } else if (tripped_) {
    s.command_mm = s.displacement_mm;  // e-stop: the actuator holds where it is
  }
  s.displacement_mm += (s.command_mm - s.displacement_mm) * (1.0 - std::exp(-dt / p_.lag_s));
  const double f = specimen_.step(s.displacement_mm);
  s.force_N = f + p_.noise_N * noise_(rng_) + p_.drift_N_per_s * s.time_s;
  if (!tripped_ && std::fabs(s.displacement_mm) > p_.limit_mm) {
    tripped_ = true;
    s.fault_code = kDisplacementLimit;
  }
  if (!tripped_ && std::fabs(s.force_N) > p_.load_cell_range_N) {
    tripped_ = true;
    s.fault_code = kForceLimit;
  }
  const bool moving = std::fabs(s.command_mm - s.displacement_mm) > 1e-4 || (driving && s.command_mm != cmd_.setpoint_mm);
  s.status_word = static_cast<std::uint16_t>(
      st::ready | (cmd_.enable && !tripped_ ? st::enabled : 0U) | (cmd_.hold ? st::holding : 0U) |
      (cmd_.estop || s.fault_code == kEstopPressed ? st::estop : 0U) |
      (s.fault_code == kDisplacementLimit || s.fault_code == kForceLimit ? st::limit_tripped : 0U) |
      (tripped_ ? st::fault : 0U) | (moving ? st::moving : 0U));
  ++s.heartbeat;
  ++s.sample_counter;
}

}  // namespace hystlab::sim
