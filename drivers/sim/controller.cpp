#include "controller.hpp"

#include "hystlab/protocols/signals.hpp"

namespace hystlab::sim {
namespace st = protocols::status;

void Controller::command(const HostCommands& c, double now_s, bool cause_present) noexcept {
  mode_ = c.mode;
  if (c.estop) press_estop();  // a level: released only by a reset, never by estop = 0
  if (c.fault_reset && !reset_was_ && !c.estop) reset(cause_present);
  reset_was_ = c.fault_reset;
  // After a reset the enable command counts only from a fresh rising edge: a host that still
  // holds enable at 1 does not restart the drive by accident.
  if (!c.enable) enable_seen_low_ = true;
  enable_ = c.enable && enable_seen_low_;
  if (c.host_heartbeat != heartbeat_) {  // the register starts at 0: the first change arms the watchdog
    heartbeat_ = c.host_heartbeat;
    heartbeat_armed_ = true;
    heartbeat_at_ = now_s;
  }
}

void Controller::reset(bool cause_present) noexcept {
  estop_ = false;
  if (cause_present && code_ == kDisplacementLimit && p_.limit_recovery) recovering_ = true, code_ = kNoFault;
  if (!cause_present) code_ = kNoFault;
  enable_ = false;
  enable_seen_low_ = false;
}

void Controller::press_estop() noexcept {
  estop_ = true;
  latch(kEstopPressed);
}

void Controller::latch(std::uint16_t code) noexcept {
  if (code_ == kNoFault && code != kNoFault) code_ = code;  // the first fault is the one to read
}

void Controller::watch(double now_s) noexcept {
  const bool on = drive_on();
  if (on && !was_on_) heartbeat_at_ = now_s;  // the watchdog times only while the drive is on
  was_on_ = on;
  if (on && heartbeat_armed_ && p_.host_timeout_s > 0 && now_s - heartbeat_at_ > p_.host_timeout_s) latch(kHostHeartbeatLost);
}

unsigned Controller::status_bits() const noexcept {
  return (stopped() ? 0U : st::ready) | (drive_on() ? st::enabled : 0U) | (estop_ ? st::estop : 0U) |
         (code_ == kDisplacementLimit || code_ == kForceLimit || recovering_ ? st::limit_tripped : 0U) | (code_ != kNoFault ? st::fault : 0U);
}

}  // namespace hystlab::sim
