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
    out.clear();
    RigSample s;
    const std::error_code ec = read_sample(now_s, s);
    if (!ec && out.capacity() > 0) out.push_back(s);
    return ec;
  }
  [[nodiscard]] virtual bool block_reads() const noexcept { return false; }
  virtual std::error_code command_shaker(double, double, bool) noexcept { return RigError::unsupported; }
  virtual std::error_code read_shaker(double, ShakerSample&) noexcept { return RigError::unsupported; }
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
  void check(std::error_code ec, const char* what) const {
    if (ec) throw std::system_error(ec, describe() + ": " + what);
  }
};

}  // namespace hystlab::drivers
