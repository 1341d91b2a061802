#pragma once
// One interface for every rig, real or simulated (as ros2_control's hardware_interface): the
// simulated rig is the same driver talking to hystlab-sim, chosen by configuration.
// Calls come in two forms (as lely-core): noexcept returning std::error_code, and throwing.
// Time is passed in (seconds on a steady clock) so back-off and staleness are testable.
#include <cstdint>
#include <string>
#include <system_error>
#include <vector>

#include "hystlab/drivers/io_health.hpp"
#include "hystlab/drivers/rig_error.hpp"

namespace hystlab::drivers {

struct RigSample {
  double time_s = 0;  // host time of the read (the caller's clock)
  double command_mm = 0, displacement_mm = 0, force_N = 0;
  std::uint16_t status_word = 0, fault_code = 0;
  std::uint32_t heartbeat = 0, sample_counter = 0;
};

struct ShakerSample {
  double time_s = 0;
  double base_accel_m_s2 = 0, mass_accel_m_s2 = 0, base_displacement_mm = 0, mass_displacement_mm = 0;
  std::uint16_t status_word = 0, fault_code = 0;
  std::uint32_t heartbeat = 0, sample_counter = 0;
};

class Rig {
 public:
  virtual ~Rig() = default;
  virtual std::error_code connect(double now_s) noexcept = 0;
  virtual void disconnect() noexcept = 0;
  virtual std::error_code arm(bool enable) noexcept = 0;  // drive enable on/off
  virtual std::error_code command(double setpoint_mm, double ramp_rate_mm_s) noexcept = 0;
  virtual std::error_code hold(bool on) noexcept = 0;
  virtual std::error_code estop(bool on) noexcept = 0;
  virtual std::error_code read_sample(double now_s, RigSample& out) noexcept = 0;
  // Every sample since the last call, oldest first (out is cleared; its capacity is reused).
  // A rig that only knows its latest value gives that one (read_sample). A rig with block reads
  // gives what its controller buffered on its own clock, time_s from the controller's counter:
  // a late caller loses nothing until the controller's buffer overruns (counted in health()).
  virtual std::error_code read_samples(double now_s, std::vector<RigSample>& out) noexcept {
    return latest_as_block(out, [&](RigSample& s) { return read_sample(now_s, s); });
  }
  [[nodiscard]] virtual bool block_reads() const noexcept { return false; }
  // What a real controller needs beyond motion. Each answers RigError::unsupported when the rig
  // (its map) has no such signal; the supervisor then skips that step and says so.
  // The operating mode (the map's `mode`): a controller moves only in the mode it was set to.
  virtual std::error_code set_mode(std::uint16_t) noexcept { return RigError::unsupported; }
  // The operator's reset: releases the e-stop signal and pulses the map's `fault_reset` (1, then
  // 0), so the controller clears its latched faults. Default: release the e-stop only.
  virtual std::error_code reset_faults() noexcept { return estop(false); }
  // The host's heartbeat (the map's `host_heartbeat`), which a controller can watch to stop on
  // its own when the host is gone.
  virtual std::error_code write_host_heartbeat(std::uint32_t) noexcept { return RigError::unsupported; }
  // The text of a controller fault code (the map's `fault_codes`); empty when unknown.
  [[nodiscard]] virtual std::string fault_text(std::uint16_t) const { return {}; }
  virtual std::error_code command_shaker(double, double, bool) noexcept { return RigError::unsupported; }
  virtual std::error_code read_shaker(double, ShakerSample&) noexcept { return RigError::unsupported; }
  // A shaker's read_samples: every sample since the last call, oldest first, as above (a rig
  // without block reads gives its latest, read_shaker).
  virtual std::error_code read_shaker_samples(double now_s, std::vector<ShakerSample>& out) noexcept {
    return latest_as_block(out, [&](ShakerSample& s) { return read_shaker(now_s, s); });
  }
  [[nodiscard]] virtual IoHealthSnapshot health() const noexcept = 0;
  [[nodiscard]] virtual std::string describe() const = 0;

  // Throwing forms: std::system_error carrying the same code.
  void connect_or_throw(double now_s) { check(connect(now_s), "connect"); }
  RigSample read_or_throw(double now_s) {
    RigSample s;
    check(read_sample(now_s, s), "read");
    return s;
  }
  void command_or_throw(double setpoint_mm, double ramp_rate_mm_s) { check(command(setpoint_mm, ramp_rate_mm_s), "command"); }

 private:
  // The latest sample as a block of one (out cleared; nothing added when its capacity is 0: the
  // caller's buffer never grows here).
  template <class Sample, class Read>
  static std::error_code latest_as_block(std::vector<Sample>& out, Read read) noexcept {
    out.clear();
    Sample s;
    const std::error_code ec = read(s);
    if (!ec && out.capacity() > 0) out.push_back(s);
    return ec;
  }
  void check(std::error_code ec, const char* what) const {
    if (ec) throw std::system_error(ec, describe() + ": " + what);
  }
};

}  // namespace hystlab::drivers
