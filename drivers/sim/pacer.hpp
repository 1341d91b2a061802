#pragma once
// A time-scaled simulator's world, paced by its host: a co-simulation barrier.
//
// No real controller runs faster than the wall clock; a time scale above 1 is a test
// accelerator. With it, a host starved for a moment (on CI VMs, 1 ms sleeps were seen to wake
// 0.5-1 s late with the machine idle) would leave minutes of rig time unobserved at time scale
// 200: a FOT row passed by with no sample in it. Paced, the world runs at most a few of the
// host's request intervals past its last request, then waits for the next one; the time it
// waited is counted as lost. At time scale 1 the world runs freely, as a real controller's does.
#include <array>
#include <cstddef>

namespace hystlab::sim {

class Pacer {
 public:
  explicit Pacer(bool on) noexcept : on_(on) {}
  [[nodiscard]] bool on() const noexcept { return on_; }
  // The wall time up to which the world may run now (now itself when not pacing).
  [[nodiscard]] double horizon(double now) const noexcept;
  // A request from the host at wall time now. world_wall is the wall time the world has run up
  // to; the returned one is where it goes on from (the wall time the host was silent, skipped).
  double on_request(double now, double world_wall) noexcept;
  [[nodiscard]] double lost_s() const noexcept { return lost_s_; }
  // How far past the host's last request the world may run: three times the median of the
  // last 8 request intervals (a median: one late request does not widen it), 3 to 200 ms.
  [[nodiscard]] double window_s() const noexcept;

  static constexpr double kMinWindow_s = 0.003, kMaxWindow_s = 0.2;

 private:
  bool on_;
  double last_request_ = -1, lost_s_ = 0;
  std::array<double, 8> intervals_{};
  std::size_t count_ = 0;
};

}  // namespace hystlab::sim
