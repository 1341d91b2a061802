#include "sim_child.hpp"

#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

extern char** environ;

namespace hystlab::daemon {
namespace fs = std::filesystem;

std::string find_simulator() {
  if (const char* env = std::getenv("HYSTLAB_SIM")) return env;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec).parent_path();
  for (const fs::path& p : {self / "hystlab-sim", self / ".." / "drivers" / "sim" / "hystlab-sim"})
    if (fs::exists(p, ec)) return p.string();
  return "hystlab-sim";
}

bool SimChild::alive() {
  if (pid_ <= 0) return false;
  int st = 0;
  if (waitpid(pid_, &st, WNOHANG) == 0) return true;
  pid_ = -1;
  return false;
}

int SimChild::ensure_running() {
  if (pid_ > 0) {
    int st = 0;
    if (waitpid(pid_, &st, WNOHANG) == 0) return port_;  // still alive
    pid_ = -1;
  }
  int out[2];
  if (pipe(out) != 0) throw std::runtime_error("hystlabd: cannot create a pipe for hystlab-sim");
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, out[1], 1);
  posix_spawn_file_actions_addclose(&fa, out[0]);
  std::string exe = find_simulator(), scale = std::to_string(opt_.time_scale), noise = std::to_string(opt_.noise_N),
              corner = std::to_string(opt_.corner_width_mm);
  std::vector<std::string> args{exe, "--port", "0",     "--time-scale", scale, "--noise", noise, "--corner-width", corner, "--exit-with-parent",
                                "1", "--rig",  opt_.rig};
  // --realtime only when configured: at a large time scale the physics catch-up is real work, and
  // at SCHED_FIFO it starved the daemon's other threads (a campaign stalled in a sanitizer build).
  if (opt_.host_timeout_ms > 0) args.insert(args.end(), {"--host-timeout-ms", std::to_string(opt_.host_timeout_ms)});
  if (opt_.realtime_priority > 0) args.insert(args.end(), {"--realtime", std::to_string(opt_.realtime_priority)});
  if (opt_.shakedown_extra_N > 0)
    args.insert(args.end(), {"--shakedown", std::to_string(opt_.shakedown_extra_N) + "," + std::to_string(opt_.shakedown_tau_cycles)});
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  // Normal scheduling unless asked: the caller may be an acquisition thread at SCHED_FIFO.
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sched_param normal{};
  posix_spawnattr_setschedpolicy(&attr, SCHED_OTHER);
  posix_spawnattr_setschedparam(&attr, &normal);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSCHEDULER);
  const int rc = posix_spawnp(&pid_, exe.c_str(), &fa, &attr, argv.data(), environ);
  posix_spawnattr_destroy(&attr);
  posix_spawn_file_actions_destroy(&fa);
  close(out[1]);
  if (rc == 0 && opt_.cpu >= 0 && !pin_process(pid_, opt_.cpu)) spdlog::info("hystlab-sim: not pinned to CPU {} (refused)", opt_.cpu);
  if (rc != 0) {
    close(out[0]);
    pid_ = -1;
    throw std::runtime_error("hystlabd: cannot start the simulator '" + exe + "' (set HYSTLAB_SIM)");
  }
  std::string text;
  pollfd p{out[0], POLLIN, 0};
  char c = 0;
  while (text.find("ready\n") == std::string::npos && poll(&p, 1, 5000) > 0 && read(out[0], &c, 1) == 1) text += c;
  close(out[0]);  // the simulator writes nothing more
  const auto at = text.find("modbus-tcp ");
  if (at == std::string::npos) {
    stop();
    throw std::runtime_error("hystlabd: the simulator did not start");
  }
  const auto colon = text.find(':', at);
  port_ = std::stoi(text.substr(colon + 1));
  return port_;
}

void SimChild::stop() {
  if (pid_ > 0) {
    kill(pid_, SIGTERM);
    int st = 0;
    waitpid(pid_, &st, 0);
    pid_ = -1;
  }
}

}  // namespace hystlab::daemon
