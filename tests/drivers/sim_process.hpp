#pragma once
// hystlab-sim as a child process for tests and benchmarks: spawned with arguments, its
// endpoints read from its first lines, stopped with SIGTERM. A fd can be handed to it as fd 3.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>
#include "../support/build_paths.hpp"

extern char** environ;

namespace hystlab::test {

class SimProcess {
 public:
  // inherit_fd >= 0 becomes fd 3 in the child (pass "--can-fd 3").
  explicit SimProcess(std::vector<std::string> args, int inherit_fd = -1) {
    int out[2];
    if (pipe(out) != 0) throw std::runtime_error("pipe");
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, out[1], 1);
    if (inherit_fd >= 0) posix_spawn_file_actions_adddup2(&fa, inherit_fd, 3);
    std::vector<char*> argv;
    static std::string exe = HYSTLAB_SIM;
    argv.push_back(exe.data());
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    if (posix_spawn(&pid_, exe.c_str(), &fa, nullptr, argv.data(), environ) != 0) throw std::runtime_error("spawn hystlab-sim");
    posix_spawn_file_actions_destroy(&fa);
    close(out[1]);
    out_ = out[0];
    for (std::string line; (line = read_line(5000)) != "ready";) {
      if (line.empty()) throw std::runtime_error("hystlab-sim did not start");
      if (line.rfind("modbus-tcp ", 0) == 0) modbus_port = std::stoi(line.substr(line.rfind(':') + 1));
      if (line.rfind("modbus-rtu ", 0) == 0) rtu_path = line.substr(11);
      if (line.rfind("control ", 0) == 0) control_port = std::stoi(line.substr(line.rfind(':') + 1));
    }
  }
  ~SimProcess() {
    if (control_fd_ >= 0) close(control_fd_);
    kill(pid_, SIGTERM);
    int st = 0;
    waitpid(pid_, &st, 0);
    close(out_);
  }
  SimProcess(const SimProcess&) = delete;
  SimProcess& operator=(const SimProcess&) = delete;

  // Sends one control line and returns the answer line.
  std::string control(const std::string& line) {
    if (control_fd_ < 0) {
      control_fd_ = socket(AF_INET, SOCK_STREAM, 0);
      sockaddr_in sa{};
      sa.sin_family = AF_INET;
      sa.sin_port = htons(static_cast<std::uint16_t>(control_port));
      sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      if (connect(control_fd_, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0) throw std::runtime_error("control connect");
    }
    const std::string l = line + "\n";
    if (write(control_fd_, l.data(), l.size()) != static_cast<ssize_t>(l.size())) throw std::runtime_error("control write");
    std::string answer;
    char c = 0;
    pollfd p{control_fd_, POLLIN, 0};
    while (poll(&p, 1, 2000) > 0 && read(control_fd_, &c, 1) == 1 && c != '\n') answer += c;
    return answer;
  }

  int modbus_port = 0, control_port = 0;
  std::string rtu_path;

  [[nodiscard]] pid_t pid() const noexcept { return pid_; }

 private:
  std::string read_line(int timeout_ms) {
    std::string line;
    char c = 0;
    pollfd p{out_, POLLIN, 0};
    while (poll(&p, 1, timeout_ms) > 0 && read(out_, &c, 1) == 1 && c != '\n') line += c;
    return line;
  }
  pid_t pid_ = -1;
  int out_ = -1, control_fd_ = -1;
};

inline double steady_now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

}  // namespace hystlab::test
