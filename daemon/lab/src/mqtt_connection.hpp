#pragma once
// RAII over one libmosquitto client (struct mosquitto), driven from a single thread: the
// publisher's. No mosquitto_loop_start: the publisher calls loop() itself, so every callback runs
// on its thread and nothing here needs a lock.
#include <string>

#include "hystlab/lab/lab_config.hpp"

struct mosquitto;

namespace hystlab::lab::detail {

// What the connection reports, called from inside MqttConnection::loop() (and connect()).
class MqttListener {
 public:
  virtual void on_connack(int rc) noexcept = 0;     // 0: accepted; else the broker's reason
  virtual void on_disconnect(int rc) noexcept = 0;  // 0: asked for; else lost
  virtual void on_published(int mid) noexcept = 0;  // QoS 0: written to the socket; QoS 1: PUBACK
  // A message of a subscription (the lab view's watch; the publisher subscribes to nothing).
  virtual void on_message(const std::string& topic, const std::string& payload) noexcept {
    (void)topic;
    (void)payload;
  }

 protected:
  ~MqttListener() = default;
};

class MqttConnection {
 public:
  // The will (retained, QoS 1) is what the broker publishes when this client vanishes without a
  // DISCONNECT (a crash, kill -9, a lost network); an empty will_topic: none. Throws std::runtime_error naming the config's
  // field when libmosquitto refuses a setting (a TLS file it cannot read, say).
  MqttConnection(const MqttSettings& s, const std::string& will_topic, const std::string& will_payload, MqttListener& listener, bool clean = true);
  ~MqttConnection();
  MqttConnection(const MqttConnection&) = delete;
  MqttConnection& operator=(const MqttConnection&) = delete;

  // A non-blocking connect (the TCP handshake and CONNACK complete in loop()); MOSQ_ERR_* code.
  [[nodiscard]] int connect() noexcept;
  // Network I/O for up to timeout_ms; MOSQ_ERR_SUCCESS, or why the connection is gone.
  [[nodiscard]] int loop(int timeout_ms) noexcept;
  [[nodiscard]] int publish(const std::string& topic, const std::string& payload, int qos, bool retain, int* mid) noexcept;
  [[nodiscard]] int subscribe(const std::string& pattern, int qos) noexcept;
  void disconnect() noexcept;
  // Bytes of packets libmosquitto still holds for the socket (0: all written).
  [[nodiscard]] bool wants_write() const noexcept;

  // libmosquitto's words for a MOSQ_ERR_* code of the last call here (MOSQ_ERR_ERRNO: its errno,
  // kept right after the call), or for a CONNACK code.
  [[nodiscard]] std::string error_text(int rc) const;
  [[nodiscard]] static std::string connack_text(int rc);

 private:
  mosquitto* m_ = nullptr;
  int errno_ = 0;
  MqttSettings settings_;
};

}  // namespace hystlab::lab::detail
