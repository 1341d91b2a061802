#pragma once
// One supervisor per rig: the rig's own state, apart from any campaign's, as a real controller's
// contract asks. It acts on every status bit of every sample, latches e-stops and faults until
// the operator resets them, arms only through a handshake (ready, no fault, mode, enable, then
// `enabled` seen in time), and re-asserts the rig's intended state (held, or disabled) as soon as
// the rig answers again after a lost link. Time is passed in (rig seconds), so it is tested with
// a fake clock and a fake rig; it writes to the rig through the Rig interface only.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>

#include "hystlab/domain/envelope.hpp"
#include "hystlab/drivers/rig.hpp"

namespace hystlab::daemon {

enum class RigState : std::uint8_t { disconnected, idle, arming, armed, holding, estopped, faulted, safing };
[[nodiscard]] std::string_view to_string(RigState s) noexcept;

struct RigTransition {
  double t = 0;
  RigState from{}, to{};
  std::string reason;
};

// One sample's view for supervision: the same for a load frame and a shaker.
struct StatusView {
  std::uint16_t status = 0, fault_code = 0;
  double position_mm = 0;  // load frame: displacement; shaker: unused
};

// "fault 3 (e-stop pressed), e-stop latched, not ready": every bit that matters, in words.
[[nodiscard]] std::string describe_status(std::uint16_t status, std::uint16_t code, const std::string& code_text);

class Supervisor {
 public:
  using Observer = std::function<void(const RigTransition&)>;
  Supervisor(drivers::Rig& rig, domain::SupervisionSettings settings, bool shaker, Observer observer = {});

  [[nodiscard]] RigState state() const noexcept { return state_; }
  [[nodiscard]] bool latched() const noexcept { return state_ == RigState::estopped || state_ == RigState::faulted; }
  [[nodiscard]] const std::string& latch_reason() const noexcept { return latch_reason_; }
  [[nodiscard]] std::uint16_t fault_code() const noexcept { return fault_code_; }
  [[nodiscard]] const domain::SupervisionSettings& settings() const noexcept { return s_; }
  [[nodiscard]] std::uint64_t link_losses() const noexcept { return link_losses_; }
  // A campaign counts its time from its own start; the supervisor's deadlines (heartbeat, verify,
  // reset) run on the rig's time across campaigns: offset = the campaign's start in rig time.
  void set_time_offset(double offset_s) noexcept { offset_ = offset_s; }
  // Rig seconds per wall-clock second (a time-scaled simulator): handshake deadlines get at least
  // kHandshakeFloor_s of wall time.
  void set_time_scale(double scale) noexcept { time_scale_ = scale > 0 ? scale : 1.0; }
  // The simulator was restarted: a new driver; the link is new, the latch stays.
  void rebind(drivers::Rig& rig) noexcept {
    rig_ = &rig;
    reassert_pending_ = true;
    if (!latched()) state_ = RigState::disconnected;
  }

  // A read failed: the link is lost until a status arrives; the intended state is re-asserted then.
  void on_link_error(double now, std::error_code ec);
  // Every fresh sample. Returns why the running campaign must end (the rig is held, and latched
  // for an e-stop or a fault), or nothing. Also re-asserts after a lost link and verifies that a
  // disarmed rig reports not enabled.
  std::optional<std::string> on_status(double now, const StatusView& v);

  // The arming handshake: begin (refused when latched or not connected), then one step per fresh
  // sample until armed or failed (with the decoded reason); on failure the rig is disarmed.
  [[nodiscard]] std::optional<std::string> begin_arming(double now);
  enum class Arming { pending, armed, failed };
  Arming arming_step(double now, const StatusView& v, std::string& reason);

  void hold(double now, const std::string& reason);          // armed/safing -> holding (the rig's hold)
  void release(double now, const std::string& reason);       // holding -> armed (the hold released)
  void begin_safing(double now, const std::string& reason);  // -> safing (the safe ramp)
  void disarm(double now, const std::string& reason);        // -> idle: held and disabled, verified
  // The e-stop, to the rig at once from any state; latched until reset. Returns the write's
  // result: on an error the latch stands here and the e-stop is re-sent the moment the rig answers.
  std::error_code estop(double now, const std::string& reason);
  // The rig's status word has shown its e-stop bit since the last estop() (verified, not assumed).
  [[nodiscard]] bool estop_confirmed() const noexcept { return estop_confirmed_; }
  // The operator's reset: releases the rig's e-stop and fault signals; the latch clears when the
  // rig then reports ready without e-stop or fault (within reset_timeout_s), else it says why.
  void begin_reset(double now);
  [[nodiscard]] bool resetting() const noexcept { return resetting_; }
  [[nodiscard]] const std::string& reset_refusal() const noexcept { return reset_refusal_; }
  // Limit recovery, a real frame's limit override: a load frame latched for a tripped limit is
  // reset into its controller's limit recovery, enabled, ramped at the safe rate to the nearest
  // point 0.5 mm inside the configured stroke [stroke_min, stroke_max], then disabled, and unlatched
  // once the rig reports it within its limits; a frame not latched but outside the configured
  // stroke (left there by an e-stop on the way back) is ramped back alike. Every stop wins meanwhile: an e-stop latches as
  // ever; a fault, not-ready, a dropped enable, motion away from the target, a lost link or the
  // time running out holds and disables it, and the rig stays latched with recovery_result().
  // Refused (the reason returned, nothing written) when it does not apply.
  [[nodiscard]] std::optional<std::string> begin_recovery(double now, double stroke_min_mm, double stroke_max_mm);
  [[nodiscard]] bool recovering() const noexcept { return recovery_ != Recovery::none; }
  [[nodiscard]] const std::string& recovery_result() const noexcept { return recovery_result_; }
  // The last recovery brought the frame back (false: it was stopped, or none ran).
  [[nodiscard]] bool recovered() const noexcept { return recovered_; }
  // The last status the supervisor saw (what a command that depends on it decides from).
  [[nodiscard]] const StatusView& last_status() const noexcept { return last_; }
  // The host heartbeat, at its period (skipped for good when the rig has none), on the host's
  // monotonic clock in seconds, not the rig's: at time scale 200 a rig-time period of 100 ms came
  // every tick, doubled the Modbus traffic and gave write timeouts (stop 16's campaign tests).
  void heartbeat(double wall_s);
  // A campaign that is not moving the rig: idle states accept new work.
  [[nodiscard]] bool moving_state() const noexcept {
    return state_ == RigState::arming || state_ == RigState::armed || state_ == RigState::holding || state_ == RigState::safing;
  }

 private:
  [[nodiscard]] double deadline(double now, double timeout_s) const noexcept;
  void go(double now, RigState to, const std::string& reason);
  void latch(double now, RigState to, const std::string& reason, std::uint16_t code);
  bool write_hold() noexcept;     // the rig's hold (a shaker: zero drive)
  bool write_disable() noexcept;  // hold and enable off (a shaker: drive off)
  void reassert(double now);
  std::optional<std::string> check_bits(double now, const StatusView& v);
  void reset_step(double now, const StatusView& v);
  void unlatch_idle(double now, const std::string& why);
  void disarm_at(double now, const std::string& reason);
  enum class Recovery : std::uint8_t { none, resetting, enabling, moving };
  void recovery_step(double now, const StatusView& v);
  void recovery_enable(double now, const StatusView& v);
  bool recovery_moving(double now, const StatusView& v);
  void recovery_done(double now, const std::string& result);
  void recovery_failed(double now, const std::string& why);

  drivers::Rig* rig_;
  double offset_ = 0;
  double time_scale_ = 1.0;
  domain::SupervisionSettings s_;
  bool shaker_;
  Observer observer_;
  RigState state_ = RigState::disconnected;
  RigState intended_ = RigState::idle;  // what the rig should be doing when the link is back
  bool reassert_pending_ = true;        // write the intended state at the next answer
  bool verify_disabled_ = false;
  double verify_deadline_ = 0;
  std::string latch_reason_;
  std::uint16_t fault_code_ = 0;
  bool arming_written_ = false;
  int arming_retries_ = 0;     // handshakes written again after a lost answer (arming_step)
  bool mode_written_ = false;  // the map has a mode register and it was written on arming
  double arming_deadline_ = 0;
  bool resetting_ = false;
  double reset_deadline_ = 0;
  std::string reset_refusal_;
  bool heartbeat_supported_ = true;
  double next_heartbeat_ = 0;
  std::uint32_t heartbeat_count_ = 0;
  std::uint64_t link_losses_ = 0;
  bool estop_confirmed_ = false;
  StatusView last_;
  bool have_last_ = false;
  Recovery recovery_ = Recovery::none;
  double recovery_target_ = 0, recovery_closest_ = 0, recovery_deadline_ = 0, stroke_min_ = 0, stroke_max_ = 0;
  std::string recovery_result_;
  bool recovered_ = false;
};

}  // namespace hystlab::daemon
