#include "control_channel.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <stdexcept>

namespace hystlab::sim {

ControlChannel::ControlChannel(int port) {
  listen_fd_ = socket(AF_INET, SOCK_STREAM, 0);
  const int one = 1;
  setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);  // loopback only: faults are a test tool
  sa.sin_port = htons(static_cast<std::uint16_t>(port));
  if (bind(listen_fd_, reinterpret_cast<sockaddr*>(&sa), sizeof sa) < 0 || listen(listen_fd_, 4) < 0)
    throw std::runtime_error("hystlab-sim: cannot listen for control on port " + std::to_string(port));
  socklen_t len = sizeof sa;
  getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&sa), &len);
  port_ = ntohs(sa.sin_port);
}

ControlChannel::~ControlChannel() {
  if (client_ >= 0) close(client_);
  if (listen_fd_ >= 0) close(listen_fd_);
}

void ControlChannel::fds(std::vector<int>& out) const {
  out.push_back(listen_fd_);
  if (client_ >= 0) out.push_back(client_);
}

bool ControlChannel::owns(int fd) const noexcept { return fd == listen_fd_ || (fd == client_ && fd >= 0); }

bool ControlChannel::handle(int fd, Faults& faults, SimRig& rig, const std::string& status) {
  if (fd == listen_fd_) {
    const int c = accept(listen_fd_, nullptr, nullptr);
    if (c < 0) return false;
    if (client_ >= 0) close(client_);  // one operator at a time: the newest wins
    client_ = c;
    buffer_.clear();
    return false;
  }
  char buf[512];
  const ssize_t n = read(client_, buf, sizeof buf);
  if (n <= 0) {
    close(client_);
    client_ = -1;
    return false;
  }
  buffer_.append(buf, static_cast<std::size_t>(n));
  bool quit = false;
  for (auto nl = buffer_.find('\n'); nl != std::string::npos; nl = buffer_.find('\n')) {
    std::string line = buffer_.substr(0, nl);
    buffer_.erase(0, nl + 1);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::string answer;
    if (line == "status")
      answer = "ok " + status + " faults: " + faults.describe() + " controller: " + rig.describe_controller();
    else if (line == "quit")
      answer = "ok bye", quit = true;
    else if (line == "clear")
      answer = "ok " + faults.apply("clear");  // latched controller faults stay: they need fault_reset
    else if (line.rfind("fault ", 0) == 0) {
      std::string spec = line.substr(6);
      if (const auto sp = spec.find(' '); sp != std::string::npos) spec[sp] = '=';
      const std::string err = apply_fault(spec, faults, rig);
      answer = err.empty() ? "ok " + faults.describe() + " controller: " + rig.describe_controller() : "error " + err;
    } else
      answer = "error unknown command '" + line + "' (fault NAME [VALUE], clear, status, quit)";
    answer += "\n";
    (void)!write(client_, answer.data(), answer.size());
  }
  return quit;
}

}  // namespace hystlab::sim
