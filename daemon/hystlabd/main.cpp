// hystlabd: the hystlab daemon. SIGTERM/SIGINT: hold the rigs, finish the write batch, mark
// running campaigns interrupted, exit 0.
#include <malloc.h>
#include <signal.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <thread>

#include "hystlab/daemon/daemon.hpp"
#include "hystlab/daemon/daemon_control.hpp"
#include "hystlab/db/sqlite.hpp"
#include "hystlab/lab/lab_watch.hpp"
#include "hystlab/lab/mqtt_publisher.hpp"
#include "hystlab/lab/replication.hpp"
#include "hystlab/web/http_api.hpp"
#include "hystlab/web/lab_view.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

const char* kHelp = R"(usage: hystlabd [--config hystlab.json] [--db PATH] [--port N] [--bind ADDRESS]

Runs campaigns on rigs and stores everything in one SQLite file, and serves the HTTP/JSON API and
the page (http://127.0.0.1:8080/ by default; --port 0 picks a free port). Without a config: a
simulated load frame (time scale 10) and a simulated shaker (real time), each a hystlab-sim started
and supervised, and ./hystlab.db; a plan without a rig goes to the one of its kind. Binding beyond
loopback needs a token (http.token in the config, or $HYSTLAB_TOKEN). Submit and follow
campaigns from the page, the API (docs/API.md) or 'hystlab campaign ...'. SIGTERM or SIGINT
stops it cleanly.
)";
}  // namespace

// A lab section and no rigs: the read-only view of the lab (docs/LAB.md), no rig and no store.
int run_lab_view(const hystlab::daemon::DaemonConfig& cfg) {
  hystlab::lab::LabWatch watch(cfg.lab);
  watch.start();
  std::unique_ptr<hystlab::web::LabView> view;
  try {
    view = std::make_unique<hystlab::web::LabView>(cfg.http, cfg.lab, [&watch] { return watch.snapshot(); });
  } catch (const std::runtime_error& e) {
    std::cerr << "hystlabd: error: " << e.what() << "\n";
    return 2;
  }
  spdlog::info("lab view of {}: serving the API and the page on http://{}:{}/", cfg.lab.name, cfg.http.bind, view->port());
  while (!g_stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(100));  // a signal's flag: nothing to wait on
  view->stop();
  watch.stop();
  return 0;
}

// glibc's allocator, set for a daemon that runs for weeks with ~190 HTTP threads (issue 40):
// - two arenas, not 8 per core: each thread that answered a request kept its own arena's high
//   water mark (15 arenas of ~5 MB each after a minute of the page's reads);
// - blocks from 256 KiB on from mmap, always: by default the threshold rises to the largest block
//   freed (up to 32 MiB), after which an answer of 10^5 points or an HDF5 export's buffers come from
//   an arena and stay resident after the request.
// bench_readers, the page's readers on a 1 kHz campaign (time scale 10): 835 -> 270 bytes a sample
// over the second half, HDF5 exports 1.19 MB -> 0.10 MB kept each. The acquisition loop allocates
// nothing per period (so sharing an arena costs it nothing); a fit's large arrays pay an mmap each.
static void set_allocator() noexcept {
  (void)mallopt(M_ARENA_MAX, 2);
  (void)mallopt(M_MMAP_THRESHOLD, 256 * 1024);
}

int main(int argc, char** argv) {
  set_allocator();
  std::string config_path, db_path, port, bind;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--help" || a == "-h") {
      std::cout << kHelp;
      return 0;
    }
    if (a == "--version") {
      std::cout << "hystlabd " << HYSTLAB_VERSION << "\n";
      return 0;
    }
    if ((a == "--config" || a == "--db" || a == "--port" || a == "--bind") && k + 1 < argc)
      (a == "--config" ? config_path : a == "--db" ? db_path : a == "--port" ? port : bind) = argv[++k];
    else {
      std::cerr << "hystlabd: error: unknown argument '" << a << "' (see --help)\n";
      return 2;
    }
  }
  struct sigaction sa {};
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
    if (!bind.empty()) cfg.http.bind = bind;
    if (!port.empty()) {
      if (port.find_first_not_of("0123456789") != std::string::npos || port.size() > 5 || std::stoi(port) > 65535)
        throw hystlab::daemon::ConfigError("--port: '" + port + "' is not a port number (0 to 65535)");
      cfg.http.port = std::stoi(port);
    }
    hystlab::daemon::check_http_security(cfg.http, std::getenv("HYSTLAB_TOKEN"));
    if (cfg.lab_view) return run_lab_view(cfg);
    hystlab::daemon::Daemon daemon(cfg);
    const auto control = hystlab::daemon::make_control(daemon);
    // The lab (docs/LAB.md): its own threads, which read the daemon only through its interface;
    // a lab server down or refusing is a status with its reason, never a reason to stop here.
    hystlab::lab::ReplicationThread replication(*control, cfg.lab, HYSTLAB_VERSION);
    replication.start();
    // Every rig live over the lab's MQTT broker: an unreachable broker only makes it retry.
    std::unique_ptr<hystlab::lab::MqttPublisher> mqtt;
    if (cfg.lab.has_mqtt) mqtt = std::make_unique<hystlab::lab::MqttPublisher>(*control, cfg.lab, control->db_path());
    auto lab_counters = [&cfg, &replication, &mqtt] {
      hystlab::control::LabCounters l;
      l.lab = cfg.lab.name, l.daemon = cfg.lab.daemon;
      l.replication = replication.counters();
      if (mqtt) l.mqtt = hystlab::lab::counters_of(mqtt->status());
      return l;
    };
    std::unique_ptr<hystlab::web::HttpApi> http;
    try {
      if (cfg.http.enabled)
        http = std::make_unique<hystlab::web::HttpApi>(*control, cfg.http, cfg.lab.enabled ? hystlab::web::HttpApi::LabSource(lab_counters) : nullptr);
    } catch (const std::runtime_error& e) {  // the port is taken (another daemon?): refused, nothing ran
      std::cerr << "hystlabd: error: " << e.what() << "\n";
      return 2;
    }
    if (mqtt) mqtt->start();
    daemon.run(g_stop);
    if (mqtt) mqtt->stop();  // "offline", retained, before the process goes
    if (http) http->stop();
    replication.stop();
    return 0;
  } catch (const hystlab::daemon::ConfigError& e) {
    std::cerr << "hystlabd: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "hystlabd: error: " << e.what() << "\n";
    return 1;
  }
}
