#pragma once
// hystlabd as a separate process, for the HTTP benchmarks and the CLI's test: started with a
// config in a temporary folder (HYSTLABD names the binary), its port read from its log, stopped
// with SIGTERM.
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>
#include "build_paths.hpp"
#include "temp_dir.hpp"

extern char** environ;

namespace hystlab::test_support {

// Starts args[0] with args, its stdout and stderr into the file `log`.
inline pid_t spawn_logged(const std::vector<std::string>& args, const std::string& log) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  std::vector<std::string> a = args;
  std::vector<char*> argv;
  for (auto& s : a) argv.push_back(s.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) throw std::runtime_error("cannot start " + args.at(0));
  return pid;
}

inline std::string read_log(const std::string& path) {
  std::stringstream s;
  s << std::ifstream(path).rdbuf();
  return s.str();
}

// The port of the hystlabd writing `log` (started with --port 0), once it serves; 0 when it has
// not said so within 60 s (a sanitized daemon on a loaded 2-core VM).
inline int served_port(const std::string& log) {
  static const std::regex re("serving the API and the page on http://127\\.0\\.0\\.1:(\\d+)/");
  for (int k = 0; k < 600; ++k) {
    std::smatch m;
    const std::string text = read_log(log);
    if (std::regex_search(text, m, re)) return std::stoi(m[1]);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return 0;
}

// A loopback port nobody listens on now, for a server a test starts next (PostgreSQL, mosquitto,
// a daemon given --port). Taken below the kernel's ephemeral range
// (/proc/sys/net/ipv4/ip_local_port_range, 32768-60999 on Debian): the kernel's own pick, as
// before, is also the local port any client connecting elsewhere may be given before the server
// binds it, and CI runs up to six tests at a time, each connecting to its rigs and daemons. Below the
// range only another test's free_port() competes (and a service with a fixed port, which can_bind
// skips), from a random start among the ~22,000 ports from 10000 up to the range.
inline int first_ephemeral_port() {
  std::ifstream f("/proc/sys/net/ipv4/ip_local_port_range");
  int lo = 32768;
  f >> lo;
  return lo;
}
// 127.0.0.1:port (0: the kernel's pick).
inline sockaddr_in loopback(int port) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  return a;
}
inline bool can_bind(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a = loopback(port);
  const bool ok = fd >= 0 && ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  if (fd >= 0) ::close(fd);
  return ok;
}
inline int free_port() {
  const int below = first_ephemeral_port();
  constexpr int kFirst = 10000;
  if (below - kFirst >= 1000) {
    std::random_device seed;
    const int span = below - kFirst;
    const int start = static_cast<int>(seed() % static_cast<unsigned>(span));
    for (int k = 0; k < span; ++k)
      if (const int port = kFirst + (start + k) % span; can_bind(port)) return port;
  }
  // A machine whose ephemeral range starts low: the kernel's pick.
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a = loopback(0);
  socklen_t len = sizeof a;
  const bool ok = fd >= 0 && ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 && ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0;
  if (fd >= 0) ::close(fd);
  if (!ok) throw std::runtime_error("free_port: no loopback port");
  return ntohs(a.sin_port);
}

inline bool accepts(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a = loopback(port);
  const bool ok = fd >= 0 && ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  if (fd >= 0) ::close(fd);
  return ok;
}

// Polls cond every `every` (20 ms) until it holds or the deadline passes; returns the last answer.
inline bool wait_until(const std::function<bool()>& cond, double seconds, std::chrono::milliseconds every = std::chrono::milliseconds(20)) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!cond()) {
    if (std::chrono::steady_clock::now() > end) return cond();
    std::this_thread::sleep_for(every);
  }
  return true;
}

// Runs args to its end, output into log; returns its exit status (-1: killed by a signal).
inline int run_logged(const std::vector<std::string>& args, const std::string& log) {
  const pid_t pid = spawn_logged(args, log);
  int status = 0;
  if (::waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

class DaemonProcess {
 public:
  // prepare: fills the database before the daemon opens it (a stored run to read back).
  explicit DaemonProcess(const std::string& config_json, const std::function<void(const std::string& db_path)>& prepare = {}) {
    if (prepare) prepare((dir_ / "bench.db").string());
    std::ofstream(dir_ / "hystlab.json") << config_json;
    const std::string log = (dir_ / "daemon.log").string();
    pid_ = spawn_logged({HYSTLABD, "--config", (dir_ / "hystlab.json").string(), "--db", (dir_ / "bench.db").string(), "--port", "0"}, log);
    port_ = served_port(log);
    if (port_ == 0) {
      const std::string text = this->log();
      stop();
      throw std::runtime_error("hystlabd did not start within 60 s; it printed:\n" + text);
    }
  }
  ~DaemonProcess() { stop(); }
  [[nodiscard]] int port() const noexcept { return port_; }
  [[nodiscard]] pid_t pid() const noexcept { return pid_; }
  // kill -9, as a crash would: nothing of the daemon's runs after it (the folder stays).
  void kill9() {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  [[nodiscard]] std::string db_path() const { return (dir_ / "bench.db").string(); }
  [[nodiscard]] std::string log() const { return read_log((dir_ / "daemon.log").string()); }

 private:
  // SIGTERM; SIGKILL when it has not exited after 30 s (a hung daemon never hangs the test).
  void stop() {
    kill(pid_, SIGTERM);
    int st = 0;
    for (int k = 0; k < 300 && waitpid(pid_, &st, WNOHANG) == 0; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (waitpid(pid_, &st, WNOHANG) == 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, &st, 0);
    }
  }

  TempDir tmp_{"daemon"};  // removed after stop(): the daemon is gone by then
  std::filesystem::path dir_ = tmp_.path();
  pid_t pid_ = -1;
  int port_ = 0;
};

}  // namespace hystlab::test_support
