// hystlabd: the hystlab daemon. SIGTERM/SIGINT: hold the rigs, finish the write batch, mark
// running campaigns interrupted, exit 0.
#include <signal.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "hystlab/daemon/daemon.hpp"
#include "hystlab/db/sqlite.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

const char* kHelp = R"(usage: hystlabd [--config hystlab.json] [--db PATH]

Runs campaigns on rigs and stores everything in one SQLite file. Without a config: one simulated
load frame (hystlab-sim, started and supervised) and ./hystlab.db. Submit and follow campaigns
with 'hystlab campaign ...'. SIGTERM or SIGINT stops it cleanly.
)";
}  // namespace

int main(int argc, char** argv) {
  std::string config_path, db_path;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--help" || a == "-h") {
      std::cout << kHelp;
      return 0;
    }
    if ((a == "--config" || a == "--db") && k + 1 < argc) (a == "--config" ? config_path : db_path) = argv[++k];
    else {
      std::cerr << "hystlabd: error: unknown argument '" << a << "' (see --help)\n";
      return 2;
    }
  }
  struct sigaction sa{};
  sa.sa_handler = on_signal;
  sigaction(SIGTERM, &sa, nullptr);
  sigaction(SIGINT, &sa, nullptr);
  signal(SIGPIPE, SIG_IGN);
  try {
    nlohmann::json j;
    std::string base = ".";
    if (!config_path.empty()) {
      std::ifstream in(config_path);
      if (!in) throw hystlab::daemon::ConfigError("cannot open config '" + config_path + "'");
      std::stringstream s;
      s << in.rdbuf();
      try {
        j = nlohmann::json::parse(s.str());
      } catch (const nlohmann::json::exception& e) {
        throw hystlab::daemon::ConfigError("config '" + config_path + "' is not valid JSON: " + e.what());
      }
      base = std::filesystem::path(config_path).parent_path().string();
      if (base.empty()) base = ".";
    }
    hystlab::daemon::DaemonConfig cfg = hystlab::daemon::parse_daemon_config(j, base);
    if (!db_path.empty()) cfg.db_path = db_path;
    return hystlab::daemon::run_daemon(cfg, g_stop);
  } catch (const hystlab::daemon::ConfigError& e) {
    std::cerr << "hystlabd: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "hystlabd: error: " << e.what() << "\n";
    return 1;
  }
}
