#pragma once
// What a real rig controller does besides the physics: latched faults with codes, a latching
// e-stop, the operator's reset, the mode interlock and the host heartbeat watchdog. Shared by
// the load frame and the shaker. Pure: time is passed in.
#include <cstdint>

namespace hystlab::sim {

enum FaultCode : std::uint16_t {
  kNoFault = 0,
  kDisplacementLimit = 1,  // |displacement| beyond the stroke limit
  kForceLimit = 2,         // |force| beyond the load cell's range
  kEstopPressed = 3,       // the e-stop signal or button
  kHostHeartbeatLost = 4,  // the host stopped changing host_heartbeat while the drive was on
  kOperatorLatch = 5,      // `fault latch` without a code: the operator's fault injection
};

struct ControllerParams {
  bool mode_interlock = false;  // the rig has a mode signal: it moves only in `mode`
  std::uint16_t mode = 1;
  double host_timeout_s = 0;   // 0: no heartbeat watchdog
  bool limit_recovery = true;  // a reset beyond the stroke enters limit recovery (a real frame's limit override)
};

// The host's commands the controller logic watches (the rest is physics).
struct HostCommands {
  bool enable = false, estop = false, fault_reset = false;
  std::uint16_t mode = 0;
  std::uint32_t host_heartbeat = 0;
};

class Controller {
 public:
  explicit Controller(ControllerParams p) : p_(p) {}
  // The host's commands as last written. A rising edge of fault_reset with the e-stop signal at 0
  // releases the e-stop latch, and clears the latched fault unless cause_present, and drops the
  // enable command (a drive never re-enables itself: the host must write enable again). A stroke
  // limit trip whose cause is present is cleared into limit recovery instead (when the controller
  // offers it): limit_tripped stays, the drive may be enabled, and the frame's owner lets it move
  // only back toward its stroke, slowly, until end_recovery().
  void command(const HostCommands& c, double now_s, bool cause_present) noexcept;
  void press_estop() noexcept;              // the operator's button: latches like the signal
  void latch(std::uint16_t code) noexcept;  // the first fault's code stays until the reset
  void watch(double now_s) noexcept;        // the heartbeat watchdog, once per sample

  [[nodiscard]] bool stopped() const noexcept { return estop_ || code_ != kNoFault; }
  [[nodiscard]] bool mode_ok() const noexcept { return !p_.mode_interlock || mode_ == p_.mode; }
  [[nodiscard]] bool drive_on() const noexcept { return enable_ && mode_ok() && !stopped(); }
  [[nodiscard]] bool enable_command() const noexcept { return enable_; }
  [[nodiscard]] std::uint16_t fault_code() const noexcept { return code_; }
  // ready, enabled, estop, limit_tripped and fault (holding and moving are the physics').
  [[nodiscard]] unsigned status_bits() const noexcept;
  [[nodiscard]] const ControllerParams& params() const noexcept { return p_; }
  [[nodiscard]] bool recovering() const noexcept { return recovering_; }
  void end_recovery() noexcept { recovering_ = false; }

 private:
  void reset(bool cause_present) noexcept;
  ControllerParams p_;
  bool enable_ = false, enable_seen_low_ = true, estop_ = false, reset_was_ = false;
  std::uint16_t code_ = kNoFault, mode_ = 0;
  std::uint32_t heartbeat_ = 0;
  bool heartbeat_armed_ = false;
  double heartbeat_at_ = 0;  // when the heartbeat last changed, or the drive came on
  bool was_on_ = false;
  bool recovering_ = false;
};

}  // namespace hystlab::sim
