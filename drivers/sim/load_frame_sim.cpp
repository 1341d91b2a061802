#include "load_frame_sim.hpp"

#include <algorithm>
#include <cmath>

#include "hystlab/protocols/signals.hpp"

namespace hystlab::sim {
namespace st = protocols::status;

SmoothedSpecimen::SmoothedSpecimen(std::unique_ptr<models::HysteresisModel> model, double width_mm) : model_(std::move(model)), width_(width_mm) {
  x_ = model_->input();
  f_ = sharp_ = model_->output();
}

double SmoothedSpecimen::step(double x) noexcept {
  const double f = model_->step(x);
  const double dx = x - x_;
  if (width_ <= 0 || dx == 0.0) {
    x_ = x;
    sharp_ = f;
    f_ = width_ > 0 ? f_ : f;
    return f_;
  }
  const int dir = dx > 0 ? 1 : -1;
  const double k = (f - sharp_) / dx;
  if (dir != dir_)
    slope_ = k;  // a reversal: the new branch's slope at once
  else
    slope_ += (k - slope_) * (1.0 - std::exp(-std::fabs(dx) / width_));
  f_ += slope_ * dx;
  f_ += (f - f_) * (1.0 - std::exp(-std::fabs(dx) / (4 * width_)));
  dir_ = dir;
  x_ = x;
  sharp_ = f;
  return f_;
}

LoadFrameSim::LoadFrameSim(std::unique_ptr<models::HysteresisModel> specimen, LoadFrameParams params)
    : p_(params), specimen_(std::move(specimen), params.corner_width_mm), ctl_(params.controller), rng_(params.seed) {
  state_.status_word = static_cast<std::uint16_t>(ctl_.status_bits());
}

void LoadFrameSim::set_commands(const LoadFrameCommands& c) noexcept {
  cmd_ = c;
  const bool was_recovering = ctl_.recovering();
  ctl_.command(HostCommands{c.enable, c.estop, c.fault_reset, c.mode, c.host_heartbeat}, state_.time_s, limit_cause_present());
  if (ctl_.recovering() && !was_recovering) recovery_closest_ = std::fabs(state_.displacement_mm);
  publish_status(false);  // a host reading right after its write sees the latch or the reset
}

void LoadFrameSim::press_estop() noexcept {
  ctl_.press_estop();
  publish_status(false);
}

void LoadFrameSim::latch_fault(std::uint16_t code) noexcept {
  ctl_.latch(code);
  publish_status(false);
}

// A reset cannot clear a limit trip while the frame is still beyond the limit.
bool LoadFrameSim::limit_cause_present() const noexcept {
  const std::uint16_t code = ctl_.fault_code();
  return (code == kDisplacementLimit && std::fabs(state_.displacement_mm) > p_.limit_mm) ||
         (code == kForceLimit && std::fabs(state_.force_N) > p_.load_cell_range_N);
}

// In limit recovery the frame may only come back: within the stroke it ends; moving out again by
// more than kRecoveryOutward from the closest it came trips the limit once more.
void LoadFrameSim::check_limits() noexcept {
  constexpr double kRecoveryOutward = 0.1;
  const double x = std::fabs(state_.displacement_mm);
  if (ctl_.recovering()) {
    recovery_closest_ = std::min(recovery_closest_, x);
    if (x <= p_.limit_mm)
      ctl_.end_recovery();
    else if (x > recovery_closest_ + kRecoveryOutward)
      ctl_.end_recovery(), ctl_.latch(kDisplacementLimit);
  } else if (x > p_.limit_mm) {
    ctl_.latch(kDisplacementLimit);
  }
  if (std::fabs(state_.force_N) > p_.load_cell_range_N) ctl_.latch(kForceLimit);
}

void LoadFrameSim::publish_status(bool driving) noexcept {
  const LoadFrameState& s = state_;
  // Inside the dead band the servo has stopped correcting: that is not motion.
  const double settled = std::max(1e-4, p_.deadband_mm);
  const bool moving = std::fabs(s.command_mm - s.displacement_mm) > settled || (driving && s.command_mm != cmd_.setpoint_mm);
  state_.fault_code = ctl_.fault_code();
  state_.status_word = static_cast<std::uint16_t>(ctl_.status_bits() | (cmd_.hold ? st::holding : 0U) | (moving ? st::moving : 0U));
}

// The command moves toward the setpoint at the ramp rate (never faster than the valve; in limit
// recovery only toward the stroke, at most at the recovery rate), or toward an overtravel's target.
void LoadFrameSim::advance_command(double dt) noexcept {
  LoadFrameState& s = state_;
  if (ctl_.stopped()) overtravel_ = false;
  double target = cmd_.setpoint_mm, rate = std::min(std::fabs(cmd_.ramp_rate_mm_s), p_.max_rate_mm_s);
  if (overtravel_) {
    target = overtravel_to_, rate = p_.overtravel_rate_mm_s;
    if (std::fabs(target - s.command_mm) <= rate * dt) overtravel_ = false;
  } else if (!(ctl_.drive_on() && !cmd_.hold)) {
    if (ctl_.stopped()) s.command_mm = s.displacement_mm;  // a latched fault or e-stop: the actuator holds where it is
    return;
  } else if (ctl_.recovering()) {
    target = std::clamp(target, -p_.limit_mm, p_.limit_mm);
    rate = std::min(rate, p_.recovery_rate_mm_s);
  }
  s.command_mm += std::clamp(target - s.command_mm, -rate * dt, rate * dt);
}

void LoadFrameSim::step(double dt) noexcept {
  LoadFrameState& s = state_;
  s.time_s += dt;
  advance_command(dt);
  const double error = s.command_mm - s.displacement_mm;
  if (std::fabs(error) >= p_.deadband_mm) s.displacement_mm += error * (1.0 - std::exp(-dt / p_.lag_s));
  const double f = specimen_.step(s.displacement_mm);
  s.force_N = f + p_.noise_N * noise_(rng_) + p_.drift_N_per_s * s.time_s;
  check_limits();
  ctl_.watch(s.time_s);
  publish_status(ctl_.drive_on() && !cmd_.hold);
  ++s.heartbeat;
  ++s.sample_counter;
}

}  // namespace hystlab::sim
