#pragma once
// hystlab-sim as a supervised child of the daemon (the embedded default rig).
#include <sys/types.h>

#include <string>

#include "hystlab/daemon/config.hpp"

namespace hystlab::daemon {

class SimChild {
 public:
  explicit SimChild(SimulatorOptions options) : opt_(options) {}
  ~SimChild() { stop(); }
  SimChild(const SimChild&) = delete;
  SimChild& operator=(const SimChild&) = delete;
  // Starts it (again) if it is not running; returns its Modbus TCP port. Throws on failure.
  int ensure_running();
  void stop();
  [[nodiscard]] bool alive();  // false once it has exited (reaped here)
  [[nodiscard]] int port() const noexcept { return port_; }

 private:
  SimulatorOptions opt_;
  pid_t pid_ = -1;
  int port_ = 0;
};

// hystlab-sim beside this executable (installed or in the build tree), or $HYSTLAB_SIM, or PATH.
[[nodiscard]] std::string find_simulator();

}  // namespace hystlab::daemon
