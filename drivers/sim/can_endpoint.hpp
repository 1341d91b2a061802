#pragma once
// The simulator's CAN side: cyclic status frames out, command frames in, on a file descriptor
// carrying struct can_frame (a socketpair end in tests; a bound CAN_RAW socket on real hardware).
#include "sim_rig.hpp"

namespace hystlab::sim {

class CanEndpoint {
 public:
  CanEndpoint(int fd, int node, double rate_hz) : fd_(fd), node_(node), period_s_(1.0 / rate_hz) {}
  [[nodiscard]] int fd() const noexcept { return fd_; }
  void receive(SimRig& rig);  // reads every pending frame and applies commands
  // Sends a status cycle when its period (wall time) has passed.
  void maybe_send(double now_s, const SignalValues& m, protocols::RigKind kind, const Faults& faults);
  [[nodiscard]] bool peer_gone() const noexcept { return gone_; }
  // The host has read every frame sent so far (its only sign of life on a bus it just listens
  // to; what paces a time-scaled world over CAN). True where the socket cannot tell (SIOCOUTQ).
  [[nodiscard]] bool host_caught_up() const noexcept;

 private:
  int fd_, node_;
  double period_s_, next_s_ = 0;
  std::uint8_t heartbeat_ = 0;
  bool gone_ = false;
};

}  // namespace hystlab::sim
