#include "hystlab/drivers/can_rig.hpp"

#include <spdlog/spdlog.h>

#include <chrono>

namespace hystlab::drivers {
namespace can = protocols::can;

CanRig::CanRig(std::unique_ptr<CanChannel> channel, CanRigConfig config) : channel_(std::move(channel)), cfg_(std::move(config)) {}

std::error_code CanRig::send(const can::Message& m) noexcept {
  can_frame f{};
  if (can::encode(m, cfg_.node, f)) {
    health_.record_error(RigError::out_of_range);
    return RigError::out_of_range;
  }
  const auto t0 = std::chrono::steady_clock::now();
  if (auto ec = channel_->send(f, cfg_.send_timeout_ms)) {
    health_.record_error(static_cast<RigError>(ec.value()));
    return ec;
  }
  health_.record_transaction(true, std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
  return {};
}

bool CanRig::absorb(const can_frame& f, bool shaker) noexcept {
  can::Message m;
  if (can::decode(f, cfg_.node, m)) {  // a frame we cannot read: count it and go on
    health_.record_error(RigError::protocol_error);
    return false;
  }
  if (auto* a = std::get_if<can::StatusA>(&m))
    pending_a_ = *a, have_a_ = true;
  else if (auto* b = std::get_if<can::StatusB>(&m))
    pending_b_ = *b, have_b_ = true;
  else if (auto* s = std::get_if<can::ShakerStatus>(&m))
    pending_shaker_ = *s, have_a_ = true;
  else if (auto* h = std::get_if<can::Heartbeat>(&m))
    heartbeat_ = h->counter;
  else if (auto* c = std::get_if<can::StatusC>(&m)) {
    const bool complete = have_a_ && (have_b_ || shaker);
    have_a_ = have_b_ = false;
    if (complete) {  // publish the cycle as a whole, never half of one
      a_ = pending_a_;
      b_ = pending_b_;
      shaker_ = pending_shaker_;
      counter_ = c->sample_counter;
      return true;
    }
  }
  return false;
}

std::error_code CanRig::next_cycle(bool shaker) noexcept {
  const auto t0 = std::chrono::steady_clock::now();
  // First what is already queued: the newest complete cycle wins (acquisition wants the latest).
  bool got = false;
  can_frame f{};
  for (;;) {
    const std::error_code ec = channel_->receive(f, 0);
    if (ec == RigError::timeout) break;
    if (ec) {
      health_.record_error(static_cast<RigError>(ec.value()));
      return ec;
    }
    got = absorb(f, shaker) || got;
  }
  // Otherwise wait for the next cycle, up to the status timeout.
  const auto deadline = t0 + std::chrono::milliseconds(cfg_.status_timeout_ms);
  while (!got) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (auto ec = channel_->receive(f, static_cast<int>(std::max<long long>(0, left)))) {
      health_.record_error(static_cast<RigError>(ec.value()));
      return ec;
    }
    got = absorb(f, shaker);
  }
  health_.record_transaction(false, std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
  return {};
}

std::error_code CanRig::connect(double) noexcept { return next_cycle(false); }

std::error_code CanRig::read_sample(double now_s, RigSample& out) noexcept {
  if (auto ec = next_cycle(false)) return ec;
  out = RigSample{now_s, b_.command_mm, a_.displacement_mm, a_.force_N, b_.status_word, b_.fault_code, heartbeat_, counter_};
  if (counter_ != last_counter_ || counter_changed_at_ < 0) {
    last_counter_ = counter_;
    counter_changed_at_ = now_s;
  } else if (now_s - counter_changed_at_ > cfg_.stale_after_s) {
    health_.record_error(RigError::stale_data);
    return RigError::stale_data;
  }
  return {};
}

std::error_code CanRig::read_shaker(double now_s, ShakerSample& out) noexcept {
  if (auto ec = next_cycle(true)) return ec;
  out = ShakerSample{now_s,
                     shaker_.base_accel_m_s2,
                     shaker_.mass_accel_m_s2,
                     shaker_.base_displacement_mm,
                     shaker_.mass_displacement_mm,
                     b_.status_word,
                     b_.fault_code,
                     heartbeat_,
                     counter_};
  return {};
}

std::error_code CanRig::arm(bool enable) noexcept {
  cmd_.enable = enable;
  return send_command();
}
std::error_code CanRig::command(double setpoint_mm, double rate) noexcept {
  cmd_.setpoint_mm = setpoint_mm;
  cmd_.ramp_rate_mm_s = rate;
  return send_command();
}
std::error_code CanRig::hold(bool on) noexcept {
  cmd_.hold = on;
  return send_command();
}
std::error_code CanRig::estop(bool on) noexcept {
  cmd_.estop = on;
  return send_command();
}
std::error_code CanRig::set_mode(std::uint16_t mode) noexcept {
  if (mode > static_cast<std::uint16_t>(can::kMaxMode)) return RigError::out_of_range;
  cmd_.mode = static_cast<std::uint8_t>(mode);
  return send_command();
}
// Releases the e-stop and pulses the reset flag. The rig drops its drive's enable on the reset,
// so ours goes to 0 too: the next arm(true) is the edge the rig needs to move again.
std::error_code CanRig::reset_faults() noexcept {
  cmd_.estop = false;
  cmd_.enable = false;
  if (auto ec = send_command()) return ec;
  cmd_.fault_reset = true;
  const std::error_code ec = send_command();
  cmd_.fault_reset = false;
  if (ec) return ec;
  return send_command();
}
std::error_code CanRig::command_shaker(double f, double a, bool enable) noexcept { return send(can::ShakerCommand{f, a, enable}); }

}  // namespace hystlab::drivers
