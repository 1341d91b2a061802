#include "hystlab/daemon/supervisor.hpp"

#include <algorithm>
#include <cstdio>

#include "hystlab/protocols/signals.hpp"

namespace hystlab::daemon {
namespace st = protocols::status;

std::string_view to_string(RigState s) noexcept {
  switch (s) {
    case RigState::disconnected:
      return "disconnected";
    case RigState::idle:
      return "idle";
    case RigState::arming:
      return "arming";
    case RigState::armed:
      return "armed";
    case RigState::holding:
      return "holding";
    case RigState::estopped:
      return "estopped";
    case RigState::faulted:
      return "faulted";
    case RigState::safing:
      return "safing";
  }
  return "unknown";
}

std::string describe_status(std::uint16_t status, std::uint16_t code, const std::string& code_text) {
  std::string out;
  auto add = [&](const std::string& part) { out += (out.empty() ? "" : ", ") + part; };
  if (code != 0)
    add("fault " + std::to_string(code) + (code_text.empty() ? "" : " (" + code_text + ")"));
  else if (status & st::fault)
    add("fault");
  if (status & st::estop) add("e-stop latched");
  if (status & st::limit_tripped) add("limit tripped");
  if (!(status & st::ready)) add("not ready");
  if (out.empty()) add(status & st::enabled ? "ready, enabled" : "ready, not enabled");
  return out;
}

Supervisor::Supervisor(drivers::Rig& rig, domain::SupervisionSettings settings, bool shaker, Observer observer)
    : rig_(&rig), s_(settings), shaker_(shaker), observer_(std::move(observer)) {}

// A controller's handshake time is its own, but the answer reaches us only at our next poll: at
// time scale 200 the 1 s arming timeout is 5 ms of wall time, less than one 100 Hz poll, and a
// starved host wakes late. On a time-scaled rig kHandshakeFloor_s of wall time is the least any
// handshake gets; a real rig (time scale 1) keeps its configured timeouts exactly.
double Supervisor::deadline(double now, double timeout_s) const noexcept {
  return now + (time_scale_ > 1 ? std::max(timeout_s, domain::kHandshakeFloor_s * time_scale_) : timeout_s);
}

void Supervisor::go(double now, RigState to, const std::string& reason) {
  if (to == state_) return;
  const RigTransition t{now, state_, to, reason};
  state_ = to;
  if (observer_) observer_(t);
}

void Supervisor::latch(double now, RigState to, const std::string& reason, std::uint16_t code) {
  latch_reason_ = reason;
  fault_code_ = code;
  intended_ = to;
  resetting_ = false;
  if (recovery_ != Recovery::none) recovery_ = Recovery::none, recovery_result_ = "limit recovery stopped: " + reason;
  go(now, to, reason);
}

bool Supervisor::write_hold() noexcept {
  // A shaker's hold is zero drive with enable as the controller last reported it: never a pulse
  // of enable (stop 31 wrote enable with the zero drive, then disabled: 1-2 ms of enable at
  // start-up and after every failure); before any report (start-up), not enabled.
  if (shaker_) return !rig_->command_shaker(0.0, 0.0, have_last_ && (last_.status & st::enabled) != 0);
  return !rig_->hold(true);
}

bool Supervisor::write_disable() noexcept {
  if (shaker_) return !rig_->command_shaker(0.0, 0.0, false);
  const bool held = !rig_->hold(true);
  return !rig_->arm(false) && held;
}

void Supervisor::on_link_error(double now, std::error_code ec) {
  now += offset_;
  reassert_pending_ = true;
  if (state_ == RigState::disconnected) return;
  ++link_losses_;
  if (recovering()) recovery_failed(now, "link lost (" + ec.message() + "): held and disabled the moment the rig answers");
  if (latched()) return;                              // the latch is the supervisor's: it outlives the link
  if (moving_state()) intended_ = RigState::holding;  // whatever it was doing, it is held when it answers
  go(now, RigState::disconnected, "link lost: " + ec.message());
}

void Supervisor::reassert(double now) {
  bool ok = true;
  if (intended_ == RigState::estopped) ok = !rig_->estop(true) && ok;
  ok = write_hold() && ok;
  if (intended_ != RigState::holding) ok = write_disable() && ok;
  if (!ok) return;  // still pending: written again at the next answer
  reassert_pending_ = false;
  if (state_ != RigState::disconnected) return;
  if (intended_ == RigState::holding) {
    go(now, RigState::holding, "link back: hold re-asserted before anything else");
  } else {
    go(now, RigState::idle, "link back: rig held and disabled before anything else");
    verify_disabled_ = true;
    verify_deadline_ = deadline(now, s_.arm_timeout_s);
  }
}

std::optional<std::string> Supervisor::check_bits(double now, const StatusView& v) {
  if (latched()) return std::nullopt;
  const std::string text = rig_->fault_text(v.fault_code);
  if (v.status & st::estop) {
    (void)write_hold();
    const std::string why = "e-stop on the rig (" + describe_status(v.status, v.fault_code, text) + ")";
    latch(now, RigState::estopped, why, v.fault_code);
    return why;
  }
  if (v.status & (st::fault | st::limit_tripped)) {
    (void)write_hold();
    const std::string why =
        std::string(v.status & st::limit_tripped ? "limit tripped on the rig" : "rig fault") + ": " + describe_status(v.status, v.fault_code, text);
    latch(now, RigState::faulted, why, v.fault_code);
    return why;
  }
  if (state_ == RigState::armed || state_ == RigState::holding || state_ == RigState::safing) {
    if (!(v.status & st::ready)) {
      (void)write_hold();
      return "the rig reports not ready (" + describe_status(v.status, v.fault_code, text) + ")";
    }
    if (!(v.status & st::enabled)) {
      (void)write_hold();
      return "the rig dropped enable (" + describe_status(v.status, v.fault_code, text) + ")";
    }
  }
  return std::nullopt;
}

std::optional<std::string> Supervisor::on_status(double now, const StatusView& v) {
  now += offset_;
  if (reassert_pending_) reassert(now);
  if (state_ == RigState::estopped && (v.status & st::estop)) estop_confirmed_ = true;
  if (state_ == RigState::disconnected) return std::nullopt;  // not yet re-asserted: nothing else
  last_ = v, have_last_ = true;
  if (recovering()) {
    recovery_step(now, v);
    return std::nullopt;
  }
  if (resetting_) {
    reset_step(now, v);
    return std::nullopt;
  }
  if (auto why = check_bits(now, v)) return why;
  if (verify_disabled_ && state_ == RigState::idle) {
    if (!(v.status & st::enabled))
      verify_disabled_ = false;
    else if (now > verify_deadline_) {  // the disable did not take: write it again, and again
      (void)write_disable();
      verify_deadline_ = deadline(now, s_.arm_timeout_s);
    }
  }
  return std::nullopt;
}

std::optional<std::string> Supervisor::begin_arming(double now) {
  now += offset_;
  if (latched()) return "the rig is latched (" + latch_reason_ + "): reset it first";
  if (resetting_) return "the rig is being reset";
  if (recovering()) return "the frame is being brought back into its stroke";
  if (state_ == RigState::disconnected) return "the rig is not connected";
  if (state_ != RigState::idle) return "the rig is busy (" + std::string(to_string(state_)) + ")";
  arming_written_ = false;
  arming_retries_ = 0;
  arming_deadline_ = deadline(now, s_.arm_timeout_s);
  go(now, RigState::arming, "arming: checking ready");
  return std::nullopt;
}

Supervisor::Arming Supervisor::arming_step(double now, const StatusView& v, std::string& reason) {
  now += offset_;
  auto failed = [&](const std::string& why) {
    reason = why;
    if (!latched()) disarm_at(now, "arming failed: " + why);
    return Arming::failed;
  };
  const std::string text = rig_->fault_text(v.fault_code);
  if (v.status & (st::estop | st::fault | st::limit_tripped) || !(v.status & st::ready)) {
    const std::string why = "rig not ready: " + describe_status(v.status, v.fault_code, text);
    (void)check_bits(now, v);  // an e-stop or a fault latches here too
    return failed(why);
  }
  // Since begin_arming the link may have been lost (the state is then disconnected, and the hold
  // and the disable are re-asserted when the rig answers): nothing of the handshake may be written
  // again, and a stale enabled bit arms nothing. (A review of stop 50's retry: a controller that
  // loses write answers loses read answers too.)
  if (state_ != RigState::arming) {
    reason = "the link to the rig was lost while arming (" + std::string(to_string(state_)) + "): held and disabled";
    return Arming::failed;
  }
  if (!arming_written_) {
    std::error_code ec = rig_->set_mode(s_.mode);
    std::string what = "cannot write mode " + std::to_string(s_.mode);
    if (!ec || ec == drivers::RigError::unsupported) {
      mode_written_ = !ec;  // a map without a mode register: none is said to be set
      // The setpoint is where the rig is, before enable: a stale setpoint from an earlier campaign
      // must never become motion the moment the drive is enabled.
      ec = shaker_ ? rig_->command_shaker(0.0, 0.0, true) : rig_->command(v.position_mm, s_.safe_rate_mm_s);
      if (!ec && !shaker_) ec = rig_->hold(true);
      if (!ec && !shaker_) ec = rig_->arm(true);
      what = "cannot enable the rig";
    }
    // An answer lost (a busy controller; stop 50's clean clone: hystlab-sim missed its 50 ms three
    // times in a second beside two browsers, and the campaign failed to arm) is asked again: every
    // write of the handshake is idempotent (the mode, the setpoint where the rig is, hold, enable),
    // so the whole handshake is written again on the next tick, until the arm deadline. A refusal
    // (an exception answer) or a lost link fails at once.
    if (ec == drivers::RigError::timeout && now <= arming_deadline_) return ++arming_retries_, Arming::pending;
    if (ec) return failed(what + ": " + ec.message() + (arming_retries_ > 0 ? " (" + std::to_string(arming_retries_ + 1) + " attempts)" : std::string()));
    arming_written_ = true;
    arming_deadline_ = deadline(now, s_.arm_timeout_s);  // "within X s of enable": from this write
    return Arming::pending;
  }
  if (v.status & st::enabled) {
    if (!shaker_)
      if (auto ec = rig_->hold(false)) return failed("cannot release the hold: " + ec.message());
    intended_ = RigState::armed;
    go(now, RigState::armed, mode_written_ ? "armed: ready, mode " + std::to_string(s_.mode) + ", enabled" : std::string("armed: ready, enabled"));
    return Arming::armed;
  }
  if (now > arming_deadline_) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.3g", s_.arm_timeout_s);
    return failed("the rig did not report enabled within " + std::string(buf) + " s of enable (" + describe_status(v.status, v.fault_code, text) +
                  (mode_written_ ? "; is it in mode " + std::to_string(s_.mode) + "?)" : std::string(")")));
  }
  return Arming::pending;
}

void Supervisor::hold(double now, const std::string& reason) {
  now += offset_;
  if (!write_hold()) reassert_pending_ = true;
  if (latched()) return;
  intended_ = RigState::holding;
  if (state_ != RigState::disconnected) go(now, RigState::holding, reason);
}

void Supervisor::release(double now, const std::string& reason) {
  now += offset_;
  if (latched() || state_ == RigState::disconnected) return;
  if (!shaker_ && rig_->hold(false)) return;  // still held: the caller sees the state unchanged
  intended_ = RigState::armed;
  go(now, RigState::armed, reason);
}

void Supervisor::begin_safing(double now, const std::string& reason) {
  now += offset_;
  if (latched() || state_ == RigState::disconnected) return;
  if (!shaker_) (void)rig_->hold(false);
  intended_ = RigState::safing;
  go(now, RigState::safing, reason);
}

void Supervisor::disarm(double now, const std::string& reason) { disarm_at(now + offset_, reason); }

void Supervisor::disarm_at(double now, const std::string& reason) {
  if (!write_disable()) reassert_pending_ = true;
  verify_disabled_ = true;
  verify_deadline_ = deadline(now, s_.arm_timeout_s);
  if (latched()) return;
  intended_ = RigState::idle;
  if (state_ != RigState::disconnected) go(now, RigState::idle, reason);
}

std::error_code Supervisor::estop(double now, const std::string& reason) {
  now += offset_;
  estop_confirmed_ = false;
  intended_ = RigState::estopped;
  const std::error_code ec = rig_->estop(true);
  if (ec) reassert_pending_ = true;  // re-sent the moment the rig answers
  (void)write_hold();
  if (state_ == RigState::estopped) return ec;
  latch(now, RigState::estopped, reason, 0);
  return ec;
}

void Supervisor::begin_reset(double now) {
  now += offset_;
  reset_refusal_.clear();
  if (auto ec = rig_->reset_faults()) {
    reset_refusal_ = "reset refused: the rig did not take the reset (" + ec.message() + ")";
    if (observer_) observer_({now, state_, state_, reset_refusal_});
    return;
  }
  resetting_ = true;
  reset_deadline_ = deadline(now, s_.reset_timeout_s);
  if (intended_ == RigState::estopped) intended_ = RigState::faulted;  // never re-send the e-stop the reset released
}

// The latch cleared (a reset confirmed, a frame brought back): disabled, verified, idle.
void Supervisor::unlatch_idle(double now, const std::string& why) {
  latch_reason_.clear();
  fault_code_ = 0;
  intended_ = RigState::idle;
  (void)write_disable();
  verify_disabled_ = true;
  verify_deadline_ = deadline(now, s_.arm_timeout_s);
  go(now, RigState::idle, why);
}

void Supervisor::reset_step(double now, const StatusView& v) {
  const bool clear = (v.status & st::ready) && !(v.status & (st::estop | st::fault | st::limit_tripped));
  if (clear) {
    resetting_ = false;
    unlatch_idle(now, "reset by the operator: the rig reports ready");
    return;
  }
  if (now > reset_deadline_) {
    resetting_ = false;
    reset_refusal_ = "reset refused: the rig still reports " + describe_status(v.status, v.fault_code, rig_->fault_text(v.fault_code));
    if (observer_) observer_({now, state_, state_, reset_refusal_});
  }
}

void Supervisor::heartbeat(double wall_s) {
  if (!heartbeat_supported_ || wall_s < next_heartbeat_) return;
  next_heartbeat_ = wall_s + s_.heartbeat_period_s;
  if (rig_->write_host_heartbeat(++heartbeat_count_) == drivers::RigError::unsupported) heartbeat_supported_ = false;
}

}  // namespace hystlab::daemon
