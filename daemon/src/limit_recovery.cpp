// Limit recovery: bringing a load frame that has left its stroke back into it, as a real frame's
// limit override allows (protocols/MODBUS.md, status bit 4): the operator asks, the controller is
// reset into its recovery, the drive is enabled and the frame ramped at the safe rate to just
// inside the configured stroke. The same brings back a frame left outside the configured stroke
// but inside the controller's (an e-stop on the way back leaves it there): no reset is needed. The frame stays latched until the rig reports it back: nothing
// else arms meanwhile, and every stop still wins (supervisor.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "hystlab/daemon/supervisor.hpp"
#include "hystlab/protocols/signals.hpp"

namespace hystlab::daemon {
namespace st = protocols::status;
namespace {
constexpr double kInsideMargin_mm = 0.5;   // the target: this far inside the configured stroke
constexpr double kAwayTolerance_mm = 0.1;  // motion away from the target beyond this stops it

std::string mm(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f mm", x);
  return buf;
}
}  // namespace

std::optional<std::string> Supervisor::begin_recovery(double now, double stroke_min_mm, double stroke_max_mm) {
  now += offset_;
  if (shaker_) return "a shaker has no stroke to recover: reset it instead";
  if (recovering()) return "the frame is being brought back already";
  if (resetting_) return "the rig is being reset";
  if (!have_last_ || state_ == RigState::disconnected) return "the rig is not connected";
  const bool outside = last_.position_mm < stroke_min_mm || last_.position_mm > stroke_max_mm;
  if (latched() && !(last_.status & st::limit_tripped)) return "the rig is latched for " + latch_reason_ + ", not for a tripped limit: reset it instead";
  if (!latched() && state_ != RigState::idle) return "the rig is " + std::string(to_string(state_)) + ": a campaign moves it";
  if (!latched() && !outside) return "the frame is within its stroke at " + mm(last_.position_mm) + " and nothing is latched: nothing to recover";
  if (latched())
    if (auto ec = rig_->reset_faults()) return "the rig did not take the reset (" + ec.message() + ")";
  stroke_min_ = stroke_min_mm, stroke_max_ = stroke_max_mm;
  const double margin = std::min(kInsideMargin_mm, (stroke_max_mm - stroke_min_mm) / 4);
  recovery_target_ = std::clamp(last_.position_mm, stroke_min_mm + margin, stroke_max_mm - margin);
  recovery_ = Recovery::resetting;  // unlatched, the first status finds it clear and enables
  recovery_result_.clear();
  recovered_ = false;
  reset_refusal_.clear();
  if (intended_ == RigState::estopped) intended_ = RigState::faulted;  // the reset released it: never re-sent
  recovery_deadline_ = deadline(now, s_.reset_timeout_s);
  if (observer_)
    observer_(
        {now, state_, state_, std::string("limit recovery: ") + (latched() ? "reset, then " : "") + "back to " + mm(recovery_target_) + " at the safe rate"});
  return std::nullopt;
}

void Supervisor::recovery_step(double now, const StatusView& v) {
  if (!latched() && (v.status & (st::estop | st::fault | st::limit_tripped))) {  // latched as at any time (check_bits)
    (void)check_bits(now, v);
    if (!write_disable()) reassert_pending_ = true;
    return;
  }
  if (v.status & st::estop && recovery_ != Recovery::resetting) {  // the rig's own e-stop wins
    (void)write_hold();
    latch(now, RigState::estopped, "e-stop on the rig during limit recovery (" + describe_status(v.status, v.fault_code, rig_->fault_text(v.fault_code)) + ")",
          v.fault_code);
    return;
  }
  if (recovery_ == Recovery::resetting) return recovery_enable(now, v);
  if (v.status & st::fault || !(v.status & st::ready))
    return recovery_failed(now, "the rig reports " + describe_status(v.status, v.fault_code, rig_->fault_text(v.fault_code)));
  if (recovery_ == Recovery::enabling) {
    if (!(v.status & st::enabled)) {
      if (now > recovery_deadline_) recovery_failed(now, "the rig did not report enabled after the reset");
      return;
    }
    if (rig_->hold(false) || rig_->command(recovery_target_, s_.safe_rate_mm_s)) return recovery_failed(now, "the rig did not take the ramp");
    recovery_ = Recovery::moving;
    recovery_closest_ = std::fabs(v.position_mm - recovery_target_);
    recovery_deadline_ = now + recovery_closest_ / s_.safe_rate_mm_s + s_.lag_s + s_.settle_s + s_.safe_timeout_s + domain::kHostStallAllowance_s * time_scale_;
    return;
  }
  (void)recovery_moving(now, v);
}

// After the reset: clear of faults and e-stop with the limit still tripped, the drive is enabled
// where the frame stands (held, so that a stale setpoint never becomes motion), then released.
void Supervisor::recovery_enable(double now, const StatusView& v) {
  const bool clear = (v.status & st::ready) && !(v.status & (st::estop | st::fault));
  if (!clear) {
    if (now > recovery_deadline_)
      recovery_failed(now, "the rig still reports " + describe_status(v.status, v.fault_code, rig_->fault_text(v.fault_code)) +
                               " after the reset: it offers no limit recovery here; bring the frame back with the controller's own override");
    return;
  }
  const bool outside = v.position_mm < stroke_min_ || v.position_mm > stroke_max_;
  if (!(v.status & st::limit_tripped) && !outside) return recovery_done(now, "reset: the rig reports the frame within its limits at " + mm(v.position_mm));
  (void)write_disable();  // a fresh rising edge of enable: a drive never re-enables itself after a reset
  if (auto ec = rig_->set_mode(s_.mode); ec && ec != drivers::RigError::unsupported)
    return recovery_failed(now, "cannot write mode " + std::to_string(s_.mode) + ": " + ec.message());
  if (rig_->command(v.position_mm, s_.safe_rate_mm_s) || rig_->hold(true) || rig_->arm(true)) return recovery_failed(now, "the rig did not take enable");
  recovery_ = Recovery::enabling;
  recovery_deadline_ = deadline(now, s_.arm_timeout_s);
}

bool Supervisor::recovery_moving(double now, const StatusView& v) {
  if (!(v.status & st::enabled)) return recovery_failed(now, "the rig dropped enable"), false;
  const double away = std::fabs(v.position_mm - recovery_target_);
  recovery_closest_ = std::min(recovery_closest_, away);
  if (away > recovery_closest_ + kAwayTolerance_mm)
    return recovery_failed(now, "the frame moved away from " + mm(recovery_target_) + " (at " + mm(v.position_mm) + ")"), false;
  if (!(v.status & st::limit_tripped) && away <= std::max(s_.in_position_mm, 0.02)) {
    recovery_done(now, "recovered: the frame is back within its stroke at " + mm(v.position_mm));
    return true;
  }
  if (now > recovery_deadline_) {
    const std::string where = v.status & st::limit_tripped ? "the rig still reports its limit tripped" : "short of the target";
    return recovery_failed(now, where + " at " + mm(v.position_mm) + " when the time for the ramp ran out"), false;
  }
  return false;
}

void Supervisor::recovery_done(double now, const std::string& result) {
  recovery_ = Recovery::none;
  recovered_ = true;
  recovery_result_ = result;
  if (state_ == RigState::idle && observer_) observer_({now, state_, state_, result});  // never latched: no transition to show it
  unlatch_idle(now, result);
}

void Supervisor::recovery_failed(double now, const std::string& why) {
  recovery_ = Recovery::none;
  if (!write_disable()) reassert_pending_ = true;
  recovery_result_ = "limit recovery stopped, the frame held and disabled: " + why;
  reset_refusal_ = recovery_result_;
  if (observer_) observer_({now, state_, state_, recovery_result_});
}

}  // namespace hystlab::daemon
