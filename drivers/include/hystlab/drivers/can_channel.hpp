#pragma once
// A CAN channel (as lely-core's): frames in and out with timeouts. Either a SocketCAN raw
// socket bound to an interface, or any file descriptor carrying struct can_frame datagrams
// (tests use one end of socketpair(AF_UNIX, SOCK_SEQPACKET), since this kernel has no AF_CAN).
#include <linux/can.h>

#include <memory>
#include <string>
#include <system_error>

namespace hystlab::drivers {

class CanChannel {
 public:
  virtual ~CanChannel() = default;
  virtual std::error_code send(const can_frame& frame, int timeout_ms) noexcept = 0;
  // RigError::timeout when nothing arrives in time; connection_lost when the peer is gone.
  virtual std::error_code receive(can_frame& frame, int timeout_ms) noexcept = 0;
  [[nodiscard]] virtual std::string describe() const = 0;

  void send_or_throw(const can_frame& f, int timeout_ms) {
    if (auto ec = send(f, timeout_ms)) throw std::system_error(ec, describe() + ": send");
  }
};

class FdCanChannel final : public CanChannel {
 public:
  // Takes ownership of fd (closed on destruction).
  FdCanChannel(int fd, std::string name);
  ~FdCanChannel() override;
  FdCanChannel(const FdCanChannel&) = delete;
  FdCanChannel& operator=(const FdCanChannel&) = delete;
  std::error_code send(const can_frame& frame, int timeout_ms) noexcept override;
  std::error_code receive(can_frame& frame, int timeout_ms) noexcept override;
  [[nodiscard]] std::string describe() const override { return name_; }

 private:
  int fd_;
  std::string name_;
};

// A raw CAN socket bound to the named interface. Throws std::system_error with a message that
// says what is missing (on a kernel without AF_CAN: that there is no SocketCAN support).
[[nodiscard]] std::unique_ptr<CanChannel> open_socketcan(const std::string& interface);

}  // namespace hystlab::drivers
