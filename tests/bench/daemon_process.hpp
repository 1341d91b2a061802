#pragma once
// hystlabd as a separate process for the HTTP benchmarks: started with a config in a temporary
// folder, its port read from its log, stopped with SIGTERM.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace hystlab::bench {

class DaemonProcess {
 public:
  explicit DaemonProcess(const std::string& config_json) {
    char tmpl[] = "/tmp/hystlab-bench-XXXXXX";
    dir_ = mkdtemp(tmpl);
    std::ofstream(dir_ / "hystlab.json") << config_json;
    const std::string log = (dir_ / "daemon.log").string();
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    std::vector<std::string> args{HYSTLABD, "--config", (dir_ / "hystlab.json").string(), "--db", (dir_ / "bench.db").string(), "--port", "0"};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    if (posix_spawn(&pid_, argv[0], &fa, nullptr, argv.data(), environ) != 0) throw std::runtime_error("cannot start hystlabd");
    posix_spawn_file_actions_destroy(&fa);
    const std::regex re("serving the API and the page on http://127\\.0\\.0\\.1:(\\d+)/");
    for (int k = 0; k < 200 && port_ == 0; ++k) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      std::stringstream s;
      s << std::ifstream(log).rdbuf();
      std::smatch m;
      const std::string text = s.str();
      if (std::regex_search(text, m, re)) port_ = std::stoi(m[1]);
    }
    if (port_ == 0) throw std::runtime_error("hystlabd did not start; see " + log);
  }
  ~DaemonProcess() {
    kill(pid_, SIGTERM);
    int st = 0;
    waitpid(pid_, &st, 0);
    std::filesystem::remove_all(dir_);
  }
  [[nodiscard]] int port() const noexcept { return port_; }

 private:
  std::filesystem::path dir_;
  pid_t pid_ = -1;
  int port_ = 0;
};

}  // namespace hystlab::bench
