#pragma once
// A small text control channel on loopback TCP, one command per line:
//   fault drop | fault delay 200 | fault exception 4 | fault crc | fault freeze | fault overload
//   fault can-silent | fault estop | fault latch [CODE] | fault deadband MM | clear | status | quit
// Each answers one line: "ok ..." or "error ...".
#include <string>
#include <vector>

#include "sim_rig.hpp"

namespace hystlab::sim {

class ControlChannel {
 public:
  explicit ControlChannel(int port);  // 0: any free port
  ~ControlChannel();
  [[nodiscard]] int port() const noexcept { return port_; }
  void fds(std::vector<int>& out) const;
  // Returns true when "quit" was received. Controller events (estop, latch, deadband) go to rig.
  bool handle(int fd, Faults& faults, SimRig& rig, const std::string& status);
  [[nodiscard]] bool owns(int fd) const noexcept;

 private:
  int listen_fd_ = -1, client_ = -1, port_ = 0;
  std::string buffer_;
};

}  // namespace hystlab::sim
