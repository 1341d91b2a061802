#pragma once
// A hystlabd of the lab as a process: a config with a lab section (the lab's PostgreSQL, and its
// broker when given), one simulated rig or none (the lab view); restartable on the same files.
// Shared by the lab tests and the lab world of the browser test (lab_world.cpp).
#include <httplib.h>
#include <signal.h>
#include <sys/wait.h>

#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "../support/build_paths.hpp"
#include "../support/daemon_process.hpp"
#include "../support/postgres_server.hpp"

namespace hystlab::lab_test {

inline const char* kFotPlan = R"({"kind": "fot", "range_mm": [0, 4], "subdivisions": 6, "ramp_rate_mm_s": 0.1, "sample_rate_hz": 500,
                                  "limits": {"displacement_mm": [-0.5, 4.5], "force_N": 400, "rate_mm_s": 50}})";

struct LabDaemonOptions {
  std::string name;  // lab.daemon; empty with view: the lab view
  std::string password_env = "HYSTLAB_TEST_PG_PASSWORD";
  int mqtt_port = 0;               // 0: no lab.mqtt
  bool view = false;               // no rigs: the lab view
  std::string rig = "load_frame";  // or "shaker"
  double time_scale = 20;
};

class LabDaemon {
 public:
  LabDaemon(const test_support::PostgresServer& pg, LabDaemonOptions o) : o_(std::move(o)), port_(test_support::free_port()) {
    nlohmann::json lab = {{"name", "materials-lab"},
                          {"daemon", o_.view ? "lab-view" : o_.name},
                          {"postgresql", pg.url()},
                          {"postgresql_password_env", o_.password_env},
                          {"replicate_every_s", 0.2}};
    if (o_.mqtt_port != 0) lab["mqtt"] = {{"host", "127.0.0.1"}, {"port", o_.mqtt_port}, {"keepalive_s", 5}};
    nlohmann::json cfg = {{"lab", lab}};
    if (!o_.view) {
      nlohmann::json sim = {{"time_scale", o_.time_scale}, {"noise_N", 0.05}};
      if (o_.rig == "shaker") sim["rig"] = "shaker";
      cfg["rigs"] = nlohmann::json::array({{{"name", o_.rig == "shaker" ? "sim shaker" : "sim frame"}, {"simulate", sim}}});
    }
    config_ = cfg;
    start();
  }
  ~LabDaemon() { stop(SIGTERM); }
  LabDaemon(const LabDaemon&) = delete;
  LabDaemon& operator=(const LabDaemon&) = delete;

  void start() {
    if (!o_.view) config_["lab"]["url"] = "http://127.0.0.1:" + std::to_string(port_) + "/";  // its page, where the lab view links
    dir_.write("hystlab.json", config_.dump());
    const std::string log = (dir_ / ("daemon" + std::to_string(++starts_) + ".log")).string();
    pid_ = test_support::spawn_logged({HYSTLABD, "--config", (dir_ / "hystlab.json").string(), "--db", db(), "--port", std::to_string(port_)}, log);
    if (test_support::served_port(log) != port_) throw std::runtime_error("hystlabd did not start: " + test_support::read_log(log));
  }
  void stop(int signal) {
    if (pid_ <= 0) return;
    kill(pid_, signal);
    int st = 0;
    if (!test_support::wait_until([&] { return waitpid(pid_, &st, WNOHANG) == pid_; }, 30)) kill(pid_, SIGKILL), waitpid(pid_, &st, 0);
    pid_ = -1;
  }
  [[nodiscard]] std::string text(const std::string& path, int* status = nullptr) const {
    httplib::Client c("127.0.0.1", port_);
    const auto r = c.Get(path);
    if (!r) throw std::runtime_error("GET " + path + ": no answer from " + o_.name);
    if (status) *status = r->status;
    return r->body;
  }
  [[nodiscard]] nlohmann::json get(const std::string& path) const { return nlohmann::json::parse(text(path)); }
  std::int64_t submit(const std::string& plan = kFotPlan) const {
    httplib::Client c("127.0.0.1", port_);
    const auto r = c.Post("/api/campaigns", nlohmann::json{{"plan", nlohmann::json::parse(plan)}}.dump(), "application/json");
    if (!r || r->status != 201) throw std::runtime_error("submit on " + o_.name + ": " + (r ? r->body : "no answer"));
    return nlohmann::json::parse(r->body).at("id").get<std::int64_t>();
  }
  [[nodiscard]] std::string db() const { return (dir_ / "hystlab.db").string(); }
  [[nodiscard]] const std::string& name() const { return o_.name; }
  [[nodiscard]] int port() const noexcept { return port_; }

 private:
  LabDaemonOptions o_;
  nlohmann::json config_;
  test_support::TempDir dir_{"labd"};
  pid_t pid_ = -1;
  int port_, starts_ = 0;  // the same port across restarts: the lab knows it
};

}  // namespace hystlab::lab_test
