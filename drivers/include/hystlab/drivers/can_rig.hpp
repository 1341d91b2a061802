#pragma once
// A rig over CAN (protocols/CAN.md): commands as frames, samples assembled from the rig's
// cyclic status frames A, B, C.
#include <memory>

#include "hystlab/drivers/can_channel.hpp"
#include "hystlab/drivers/rig.hpp"
#include "hystlab/protocols/can_protocol.hpp"

namespace hystlab::drivers {

struct CanRigConfig {
  int node = 1;
  int status_timeout_ms = 100;  // no status cycle within this: timeout (the rig went silent)
  int send_timeout_ms = 20;
  double stale_after_s = 0.5;
  std::string name = "can rig";
};

class CanRig final : public Rig {
 public:
  CanRig(std::unique_ptr<CanChannel> channel, CanRigConfig config);

  std::error_code connect(double now_s) noexcept override;  // waits for one status cycle
  void disconnect() noexcept override {}
  std::error_code arm(bool enable) noexcept override;
  std::error_code command(double setpoint_mm, double ramp_rate_mm_s) noexcept override;
  std::error_code hold(bool on) noexcept override;
  std::error_code estop(bool on) noexcept override;
  // The command frame carries the mode (0..3) and a fault reset flag (protocols/CAN.md).
  std::error_code set_mode(std::uint16_t mode) noexcept override;
  std::error_code reset_faults() noexcept override;
  std::error_code read_sample(double now_s, RigSample& out) noexcept override;
  std::error_code command_shaker(double frequency_hz, double amplitude_mm, bool enable) noexcept override;
  std::error_code read_shaker(double now_s, ShakerSample& out) noexcept override;
  [[nodiscard]] IoHealthSnapshot health() const noexcept override { return health_.snapshot(); }
  [[nodiscard]] std::string describe() const override { return cfg_.name + " (" + channel_->describe() + ")"; }

 private:
  std::error_code send(const protocols::can::Message& m) noexcept;
  std::error_code send_command() noexcept { return send(cmd_); }
  // Takes the newest complete status cycle (A, B, C) that is queued, or waits for the next one.
  std::error_code next_cycle(bool shaker) noexcept;
  bool absorb(const can_frame& f, bool shaker) noexcept;  // true when f completes a cycle

  std::unique_ptr<CanChannel> channel_;
  CanRigConfig cfg_;
  IoHealth health_;
  protocols::can::Command cmd_;
  protocols::can::StatusA a_, pending_a_;
  protocols::can::StatusB b_, pending_b_;
  protocols::can::ShakerStatus shaker_, pending_shaker_;
  std::uint32_t counter_ = 0, heartbeat_ = 0, last_counter_ = 0;
  double counter_changed_at_ = -1;
  bool have_a_ = false, have_b_ = false;
};

}  // namespace hystlab::drivers
