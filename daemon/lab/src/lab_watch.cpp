#include "hystlab/lab/lab_watch.hpp"

#include <mosquitto.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "hystlab/lab/mqtt_publisher.hpp"
#include "mqtt_connection.hpp"
#include "mqtt_payloads.hpp"

namespace hystlab::lab {
using nlohmann::json;

std::string level_name(const std::string& level) {
  std::string out;
  for (std::size_t k = 0; k < level.size(); ++k) {
    if (level[k] == '%' && k + 2 < level.size() && std::isxdigit(static_cast<unsigned char>(level[k + 1])) &&
        std::isxdigit(static_cast<unsigned char>(level[k + 2]))) {
      out += static_cast<char>(std::stoi(level.substr(k + 1, 2), nullptr, 16));
      k += 2;
    } else {
      out += level[k];
    }
  }
  return out;
}

struct LabWatch::Impl final : detail::MqttListener {
  explicit Impl(const LabConfig& c) : config(c) {
    settings = c.mqtt;
    settings.client_id += "-view";  // beside a publishing daemon of the same name, never in its place
  }
  LabConfig config;
  MqttSettings settings;
  mutable std::mutex mu;
  std::condition_variable cv;
  bool stopping = false, connected = false, subscribe_now = false;
  std::string error;
  json daemons = json::object(), rigs = json::object();
  std::thread thread;

  void on_connack(int rc) noexcept override {
    const std::lock_guard lock(mu);
    connected = rc == 0;
    subscribe_now = rc == 0;
    error = rc == 0 ? "" : "the broker refused the connection: " + detail::MqttConnection::connack_text(rc);
  }
  void on_disconnect(int rc) noexcept override {
    const std::lock_guard lock(mu);
    connected = false;
    if (rc != 0) error = "the connection to the broker was lost";
  }
  void on_published(int) noexcept override {}
  // hystlab/<lab>/<daemon>/status or hystlab/<lab>/<daemon>/<rig>/state: anything else, or a
  // payload that is not a JSON object, is left out.
  void on_message(const std::string& topic, const std::string& payload) noexcept override {
    try {
      std::vector<std::string> levels;
      for (std::size_t a = 0, b = 0; b != std::string::npos; a = b + 1) {
        b = topic.find('/', a);
        levels.push_back(topic.substr(a, b == std::string::npos ? std::string::npos : b - a));
      }
      json doc = payload.empty() ? json() : json::parse(payload, nullptr, false);
      const std::lock_guard lock(mu);
      if (levels.size() == 4 && levels[3] == "status") {
        if (!doc.is_object()) return daemons.erase(level_name(levels[2])), void();
        doc["received_at"] = detail::utc_now();
        daemons[level_name(levels[2])] = std::move(doc);
      } else if (levels.size() == 5 && levels[4] == "state") {
        if (!doc.is_object()) return;
        doc["received_at"] = detail::utc_now();
        rigs[level_name(levels[2])][level_name(levels[3])] = std::move(doc);
      }
    } catch (...) {  // a message never takes the view down
    }
  }

  bool wait(double s) {
    std::unique_lock lock(mu);
    return !cv.wait_for(lock, std::chrono::duration<double>(s), [this] { return stopping; });
  }
  bool stop_asked() {
    const std::lock_guard lock(mu);
    return stopping;
  }
  void fail(const std::string& why) {
    const std::lock_guard lock(mu);
    connected = false;
    error = why;
  }

  // One connection's life: connect, subscribe once accepted, loop until lost or stopped. True
  // when the broker accepted it.
  bool session(detail::MqttConnection& c) {
    bool accepted = false;
    const std::string prefix = "hystlab/" + topic_level(config.name) + "/";  // escaped as the daemons publish it
    if (const int rc = c.connect(); rc != MOSQ_ERR_SUCCESS) {
      fail("cannot reach the broker at " + settings.host + ":" + std::to_string(settings.port) + ": " + c.error_text(rc));
      return false;
    }
    while (!stop_asked()) {
      if (const int rc = c.loop(100); rc != MOSQ_ERR_SUCCESS) {
        fail("the broker's connection: " + c.error_text(rc));
        return accepted;
      }
      bool sub = false;
      {
        const std::lock_guard lock(mu);
        std::swap(sub, subscribe_now);
        accepted = accepted || connected;
      }
      if (sub && (c.subscribe(prefix + "+/status", 1) != MOSQ_ERR_SUCCESS || c.subscribe(prefix + "+/+/state", 1) != MOSQ_ERR_SUCCESS)) {
        fail("cannot subscribe to " + prefix + "#");
        return accepted;
      }
    }
    c.disconnect();
    return accepted;
  }

  void run() noexcept {
    double backoff = 0.5;
    while (!stop_asked()) {
      bool was_connected = false;
      try {
        detail::MqttConnection c(settings, "", "", *this);
        was_connected = session(c);
      } catch (const std::exception& e) {
        fail(e.what());
      }
      backoff = was_connected ? 0.5 : std::min(backoff * 2, 30.0);  // a broker that was up: try again soon
      if (!wait(backoff)) return;
    }
  }
};

LabWatch::LabWatch(const LabConfig& config) : impl_(std::make_unique<Impl>(config)) {}
LabWatch::~LabWatch() { stop(); }

void LabWatch::start() {
  if (!impl_->config.has_mqtt || impl_->thread.joinable()) return;
  impl_->thread = std::thread([this] { impl_->run(); });
}

void LabWatch::stop() noexcept {
  {
    const std::lock_guard lock(impl_->mu);
    impl_->stopping = true;
  }
  impl_->cv.notify_all();
  if (impl_->thread.joinable()) impl_->thread.join();
}

json LabWatch::snapshot() const {
  const std::lock_guard lock(impl_->mu);
  return {{"configured", impl_->config.has_mqtt},
          {"connected", impl_->connected},
          {"error", impl_->error.empty() ? json(nullptr) : json(impl_->error)},
          {"daemons", impl_->daemons},
          {"rigs", impl_->rigs}};
}

}  // namespace hystlab::lab
