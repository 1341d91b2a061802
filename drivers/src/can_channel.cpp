#include "hystlab/drivers/can_channel.hpp"

#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "hystlab/drivers/rig_error.hpp"

namespace hystlab::drivers {
namespace {
std::error_code wait_for(int fd, short events, int timeout_ms) {
  pollfd p{fd, events, 0};
  for (;;) {
    const int rc = ::poll(&p, 1, timeout_ms);
    if (rc > 0) {
      if (p.revents & (POLLERR | POLLNVAL)) return RigError::connection_lost;
      if (p.revents & events) return {};
      if (p.revents & POLLHUP) return RigError::connection_lost;
    }
    if (rc == 0) return RigError::timeout;
    if (errno != EINTR) return RigError::connection_lost;
  }
}
}  // namespace

FdCanChannel::FdCanChannel(int fd, std::string name) : fd_(fd), name_(std::move(name)) {}
FdCanChannel::~FdCanChannel() {
  if (fd_ >= 0) ::close(fd_);
}

std::error_code FdCanChannel::send(const can_frame& frame, int timeout_ms) noexcept {
  if (auto ec = wait_for(fd_, POLLOUT, timeout_ms)) return ec;
  const ssize_t n = ::send(fd_, &frame, sizeof frame, MSG_NOSIGNAL | MSG_DONTWAIT);
  if (n == static_cast<ssize_t>(sizeof frame)) return {};
  if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return RigError::timeout;
  return RigError::connection_lost;
}

std::error_code FdCanChannel::receive(can_frame& frame, int timeout_ms) noexcept {
  if (auto ec = wait_for(fd_, POLLIN, timeout_ms)) return ec;
  const ssize_t n = ::recv(fd_, &frame, sizeof frame, MSG_DONTWAIT);
  if (n == static_cast<ssize_t>(sizeof frame)) return {};
  if (n == 0) return RigError::connection_lost;  // the peer closed
  if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return RigError::timeout;
  if (n < 0) return RigError::connection_lost;
  return RigError::protocol_error;  // a datagram that is not a classic CAN frame
}

std::unique_ptr<CanChannel> open_socketcan(const std::string& interface) {
  const int fd = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd < 0) {
    const int err = errno;
    if (err == EAFNOSUPPORT)
      throw std::system_error(err, std::generic_category(),
                              "cannot open CAN interface '" + interface + "': this kernel has no SocketCAN support (socket(PF_CAN, SOCK_RAW, CAN_RAW) failed)");
    throw std::system_error(err, std::generic_category(), "cannot open CAN interface '" + interface + "'");
  }
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, interface.c_str(), IFNAMSIZ - 1);
  if (::ioctl(fd, SIOCGIFINDEX, &ifr) < 0) {
    const int err = errno;
    ::close(fd);
    throw std::system_error(err, std::generic_category(), "cannot open CAN interface '" + interface + "': no such interface");
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) {
    const int err = errno;
    ::close(fd);
    throw std::system_error(err, std::generic_category(), "cannot bind CAN interface '" + interface + "'");
  }
  return std::make_unique<FdCanChannel>(fd, "socketcan " + interface);
}

}  // namespace hystlab::drivers
