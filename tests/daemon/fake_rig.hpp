#pragma once
// An in-process load frame for the unit tests of the loop and the supervisor: a controller with
// the contract of a real one (ready/enabled handshake, a mode interlock, latched e-stop and
// faults cleared only by a reset, a servo dead band, hold), driven by the time passed in, with a
// fault plan (latch fault k at t, e-stop at t, drop or exceptions or a frozen counter over a
// window, a late answer, a limit trip, not ready, the host's heartbeat lost). It records what the
// host wrote, so invariants can be checked. As a shaker (shaker = true) its table follows the
// drive's amplitude with a first-order lag and the mass answers 1.5 times the base, 0.3 rad behind.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "hystlab/drivers/rig.hpp"
#include "hystlab/protocols/signals.hpp"

namespace hystlab::test {
namespace st = protocols::status;
using drivers::RigError;

struct FaultEvent {
  // The randomized schedules draw from the first six; the safety matrix uses them all.
  enum Kind { latch_fault, estop, drop, exceptions, freeze, drop_enable, limit_trip, not_ready, heartbeat_loss } kind;
  double at_s = 0, until_s = 0;  // windows: [at, until)
  std::uint16_t code = 0;
  bool applied = false;  // one-shot events (latch_fault, estop, drop_enable) happen once
};

class FakeRig final : public drivers::Rig {
 public:
  // What the host did, for the invariants.
  struct Log {
    int setpoints_while_latched = 0, enables_while_latched = 0, resets = 0, hold_writes = 0, estop_writes = 0;
    int mode_writes = 0, heartbeats = 0, disables = 0, drive_writes = 0, drives_while_latched = 0;
    int zero_drives = 0;    // a shaker's drive written with zero amplitude (its hold)
    int enable_writes = 0;  // enable written on (arm(true), or a shaker's drive with enable)
    std::vector<double> setpoints;
  } log;
  double deadband_mm = 0, rate_cap_mm_s = 500, dt = 0.001;
  double t_base = 0;               // added to the time a read passes in (campaigns count from their start)
  double enable_delay_s = 0;       // enabled reported this long after enable (the handshake's wait)
  double heartbeat_timeout_s = 0;  // > 0: the controller's host watchdog (fault 4), timed while enabled
  double stroke_mm = 1e9;          // beyond ±stroke_mm: fault 1; a reset there enters limit recovery (1 mm/s, inward only)
  bool shaker = false;
  // The next this many non-zero drive writes are taken but answered late (a timeout), as a busy
  // controller's: the host does not know the write was taken.
  int late_drive_answers = 0;
  // The next this many mode writes are taken but answered late (a timeout): arming's handshake.
  int late_mode_answers = 0;
  std::uint16_t required_mode = 1;
  std::vector<FaultEvent> plan;

  std::error_code connect(double) noexcept override { return {}; }
  void disconnect() noexcept override {}
  std::error_code arm(bool on) noexcept override {
    if (auto ec = link()) return ec;
    if (on && (estop_ || fault_)) ++log.enables_while_latched;
    if (!on) ++log.disables;
    if (on && !enable_) enabled_at_ = now_;
    if (on) ++log.enable_writes;
    enable_ = on;
    return {};
  }
  std::error_code command(double sp, double rate) noexcept override {
    if (auto ec = link()) return ec;
    if (estop_ || fault_) ++log.setpoints_while_latched;
    setpoint_ = sp, rate_ = rate;
    log.setpoints.push_back(sp);
    return {};
  }
  std::error_code hold(bool on) noexcept override {
    if (auto ec = link()) return ec;
    ++log.hold_writes;
    hold_ = on;
    return {};
  }
  std::error_code estop(bool on) noexcept override {
    if (auto ec = link()) return ec;
    ++log.estop_writes;
    estop_cmd_ = on;
    if (on) latch_estop();
    return {};
  }
  std::error_code set_mode(std::uint16_t m) noexcept override {
    if (auto ec = link()) return ec;
    ++log.mode_writes;
    mode_ = m;
    if (late_mode_answers > 0) return --late_mode_answers, RigError::timeout;
    return {};
  }
  std::error_code reset_faults() noexcept override {
    if (auto ec = link()) return ec;
    ++log.resets;
    estop_cmd_ = false;
    if (!cause_ && limit_ && beyond())
      fault_ = 0, estop_ = false, enable_ = false, recovering_ = true;
    else if (!cause_)
      fault_ = 0, estop_ = false, enable_ = false, limit_ = false;
    return {};
  }
  std::error_code write_host_heartbeat(std::uint32_t) noexcept override {
    if (auto ec = link()) return ec;
    if (in(FaultEvent::heartbeat_loss)) return RigError::timeout;  // the host's writes never arrive
    ++log.heartbeats;
    heartbeat_at_ = now_;
    return {};
  }
  std::error_code command_shaker(double f_hz, double amplitude_mm, bool enable) noexcept override {
    if (!shaker) return RigError::unsupported;
    if (auto ec = link()) return ec;
    ++log.drive_writes;
    if (amplitude_mm == 0) ++log.zero_drives;
    if ((estop_ || fault_) && amplitude_mm > 0) ++log.drives_while_latched;
    if (enable && !enable_) enabled_at_ = now_;
    if (enable) ++log.enable_writes;
    if (!enable) ++log.disables;
    enable_ = enable;
    f_hz_ = f_hz, drive_mm_ = amplitude_mm;
    if (amplitude_mm > 0 && late_drive_answers > 0) return --late_drive_answers, RigError::timeout;
    return {};
  }
  std::error_code read_shaker(double now, drivers::ShakerSample& out) noexcept override {
    if (!shaker) return RigError::unsupported;
    advance(now + t_base);
    if (auto ec = link()) return ec;
    const double w = 2 * 3.141592653589793 * f_hz_;
    out.time_s = now;
    out.base_displacement_mm = amp_ * std::sin(phase_);
    out.mass_displacement_mm = 1.5 * amp_ * std::sin(phase_ - 0.3);
    out.base_accel_m_s2 = -w * w * out.base_displacement_mm * 1e-3;
    out.mass_accel_m_s2 = -w * w * out.mass_displacement_mm * 1e-3;
    out.status_word = status();
    out.fault_code = fault_;
    if (!frozen()) ++counter_;
    out.sample_counter = counter_;
    return {};
  }
  std::string fault_text(std::uint16_t code) const override { return code == 7 ? "hydraulic pressure low" : ""; }
  std::error_code read_sample(double now, drivers::RigSample& out) noexcept override {
    advance(now + t_base);
    if (auto ec = link()) return ec;
    out.time_s = now;
    out.displacement_mm = x_;
    out.command_mm = cmd_;
    out.force_N = 20 * x_;
    out.status_word = status();
    out.fault_code = fault_;
    if (!frozen()) ++counter_;
    out.sample_counter = counter_;
    return {};
  }
  [[nodiscard]] drivers::IoHealthSnapshot health() const noexcept override { return {}; }
  [[nodiscard]] std::string describe() const override { return "fake rig"; }

  // The controller's state, for assertions.
  [[nodiscard]] bool enabled() const { return enable_ && mode_ == required_mode && !estop_ && !fault_; }
  [[nodiscard]] bool held() const { return hold_; }
  [[nodiscard]] bool latched() const { return estop_ || fault_ != 0; }
  [[nodiscard]] double position() const { return x_; }
  [[nodiscard]] bool moving() const { return moving_; }
  [[nodiscard]] double amplitude() const { return amp_; }   // the shaker table's
  [[nodiscard]] double drive() const { return drive_mm_; }  // the drive last written
  [[nodiscard]] double now() const { return now_; }
  [[nodiscard]] bool estop_commanded() const { return estop_cmd_; }
  [[nodiscard]] bool recovering() const { return recovering_; }
  void place(double x) { x_ = cmd_ = setpoint_ = x; }  // the frame put there from outside (a hand set's jog)
  void clear_cause() { cause_ = false; }
  void set_cause() { cause_ = true; }

 private:
  bool in(FaultEvent::Kind k) const {
    for (const auto& e : plan)
      if (e.kind == k && now_ >= e.at_s && now_ < e.until_s) return true;
    return false;
  }
  std::error_code link() const {
    if (in(FaultEvent::drop)) return RigError::connection_lost;
    if (in(FaultEvent::exceptions)) return RigError::exception_response;
    return {};
  }
  bool frozen() const { return in(FaultEvent::freeze); }
  bool beyond() const { return std::fabs(x_) > stroke_mm; }
  void latch_estop() {
    estop_ = true;
    if (!fault_) fault_ = 3;
  }
  void advance(double now) {
    while (now_ + dt <= now) {
      now_ += dt;
      for (auto& e : plan)
        if (now_ >= e.at_s && !e.applied) {
          e.applied = true;
          if (e.kind == FaultEvent::latch_fault) fault_ = e.code;
          if (e.kind == FaultEvent::estop) latch_estop();
          if (e.kind == FaultEvent::drop_enable) enable_ = false;
          if (e.kind == FaultEvent::limit_trip && !fault_) fault_ = 1, limit_ = true;
        }
      if (heartbeat_timeout_s > 0 && enabled() && now_ - std::max(heartbeat_at_, enabled_at_) > heartbeat_timeout_s && !fault_) fault_ = 4;
      if (shaker) {
        const double target = enabled() && !hold_ ? drive_mm_ : 0.0;
        amp_ += (target - amp_) * 0.05;  // the table's amplitude lags the drive by ~20 ms
        phase_ += 2 * 3.141592653589793 * f_hz_ * dt;
        moving_ = amp_ > 1e-4;
        continue;
      }
      const bool driving = enabled() && !hold_;
      const double before = x_;
      const double rate = std::min({rate_, rate_cap_mm_s, recovering_ ? 1.0 : 1e9});
      const double target = recovering_ ? std::clamp(setpoint_, -stroke_mm, stroke_mm) : setpoint_;
      if (driving)
        cmd_ += std::clamp(target - cmd_, -rate * dt, rate * dt);
      else
        cmd_ = x_;
      if (std::fabs(cmd_ - x_) > deadband_mm) x_ += (cmd_ - x_) * 0.2;
      moving_ = std::fabs(x_ - before) > 1e-9;
      if (recovering_ && !beyond()) recovering_ = false, limit_ = false;
      if (!recovering_ && beyond() && !fault_) fault_ = 1, limit_ = true;
    }
  }
  std::uint16_t status() const {
    const bool ready = !estop_ && !fault_ && !in(FaultEvent::not_ready);
    const bool on = enabled() && now_ - enabled_at_ >= enable_delay_s;
    return static_cast<std::uint16_t>((ready ? st::ready : 0U) | (on ? st::enabled : 0U) | (hold_ ? st::holding : 0U) | (estop_ ? st::estop : 0U) |
                                      (fault_ && !estop_ ? st::fault : 0U) | (moving_ ? st::moving : 0U) | (limit_ ? st::limit_tripped : 0U));
  }

  double now_ = 0, x_ = 0, cmd_ = 0, setpoint_ = 0, rate_ = 1;
  bool enable_ = false, hold_ = false, estop_ = false, estop_cmd_ = false, cause_ = false, moving_ = false, limit_ = false;
  bool recovering_ = false;
  double enabled_at_ = 0, heartbeat_at_ = 0, f_hz_ = 0, drive_mm_ = 0, amp_ = 0, phase_ = 0;
  std::uint16_t mode_ = 0, fault_ = 0;
  std::uint32_t counter_ = 0;
};

}  // namespace hystlab::test
