#pragma once
// The simulated world's clock: how many physics steps are due at a wall time.
//
// The controller the simulator stands in for has a CPU of its own and never misses a cycle. A
// moment the simulator is not scheduled is, on the VMs it runs on in CI, a moment the whole
// machine was not: two processes spinning on the two vCPUs lost 6.6 s of 8 s, in the same
// 0.05-0.6 s chunks. Its host froze with it; a world that jumped ahead meanwhile would be a rig
// the host could not have watched (100 s of rig time at time scale 200). So at most kMaxCatchUp_s
// of wall time (the longest wait of a simulator that is scheduled) is caught up at once; the
// rest is lost, and counted. Time-scaled, the world is also paced by its host (pacer.hpp).
// Pure: wall times come as arguments.
#include "pacer.hpp"

namespace hystlab::sim {

class WorldClock {
 public:
  WorldClock(double time_scale, double sample_dt, bool paced) noexcept : pacer_(paced), scale_(time_scale), dt_(sample_dt) {}
  // Whole physics steps due at wall time now (each of sample_dt simulated seconds).
  long steps_due(double now) noexcept;
  // A request (a sign of life) from the host at wall time now.
  void host_request(double now) noexcept { last_ = pacer_.on_request(now, last_); }
  // Wall time the world paused (a frozen machine) or waited for its host.
  [[nodiscard]] double lost_s() const noexcept { return frozen_s_ + pacer_.lost_s(); }

  static constexpr double kMaxCatchUp_s = 0.02;

 private:
  Pacer pacer_;
  double scale_, dt_;
  double due_ = 0, last_ = 0, frozen_s_ = 0;  // simulated time owed; wall time accounted up to
};

}  // namespace hystlab::sim
