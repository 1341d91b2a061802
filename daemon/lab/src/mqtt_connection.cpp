#include "mqtt_connection.hpp"

#include <mosquitto.h>

#include <cerrno>
#include <cstring>
#include <mutex>
#include <stdexcept>

namespace hystlab::lab::detail {
namespace {

// libmosquitto's global set-up, once per process. Never undone: mosquitto_lib_cleanup while
// another client (another publisher, a test's subscriber) lives would pull OpenSSL from under it.
void init_library() {
  static std::once_flag once;
  std::call_once(once, [] { mosquitto_lib_init(); });
}

MqttListener& listener_of(void* obj) noexcept { return *static_cast<MqttListener*>(obj); }

void on_connect(mosquitto*, void* obj, int rc) { listener_of(obj).on_connack(rc); }
void on_disconnect(mosquitto*, void* obj, int rc) { listener_of(obj).on_disconnect(rc); }
void on_publish(mosquitto*, void* obj, int mid) { listener_of(obj).on_published(mid); }
void on_message(mosquitto*, void* obj, const mosquitto_message* m) {
  if (m == nullptr || m->topic == nullptr) return;
  const std::string payload = m->payloadlen > 0 ? std::string(static_cast<const char*>(m->payload), static_cast<std::size_t>(m->payloadlen)) : std::string();
  listener_of(obj).on_message(m->topic, payload);
}

const char* or_null(const std::string& s) noexcept { return s.empty() ? nullptr : s.c_str(); }

void check(int rc, const std::string& field, const std::string& what) {
  if (rc != MOSQ_ERR_SUCCESS)
    throw std::runtime_error("config: lab.mqtt." + field + ": " + what + ": " + (rc == MOSQ_ERR_ERRNO ? std::strerror(errno) : mosquitto_strerror(rc)));
}
}  // namespace

MqttConnection::MqttConnection(const MqttSettings& s, const std::string& will_topic, const std::string& will_payload, MqttListener& listener, bool clean)
    : settings_(s) {
  init_library();
  // A clean session: the publisher subscribes to nothing, and a broker keeping a session for it
  // would only queue messages for a subscription it never makes.
  m_ = mosquitto_new(s.client_id.c_str(), clean, &listener);
  if (m_ == nullptr) throw std::runtime_error("config: lab.mqtt.client_id: libmosquitto cannot make a client '" + s.client_id + "': " + std::strerror(errno));
  try {
    mosquitto_connect_callback_set(m_, on_connect);
    mosquitto_disconnect_callback_set(m_, on_disconnect);
    mosquitto_publish_callback_set(m_, on_publish);
    mosquitto_message_callback_set(m_, on_message);
    if (!will_topic.empty())
      check(mosquitto_will_set(m_, will_topic.c_str(), static_cast<int>(will_payload.size()), will_payload.data(), 1, true), "client_id",
            "the will on '" + will_topic + "'");
    if (!s.username.empty()) check(mosquitto_username_pw_set(m_, s.username.c_str(), or_null(s.password)), "username", "refused");
    if (!s.ca_file.empty())
      check(mosquitto_tls_set(m_, s.ca_file.c_str(), nullptr, or_null(s.cert_file), or_null(s.key_file), nullptr), "ca_file",
            "TLS with '" + s.ca_file + "'" + (s.cert_file.empty() ? "" : " and '" + s.cert_file + "'"));
  } catch (...) {
    mosquitto_destroy(m_);
    throw;
  }
}

MqttConnection::~MqttConnection() { mosquitto_destroy(m_); }

int MqttConnection::connect() noexcept {
  const int rc = mosquitto_connect_async(m_, settings_.host.c_str(), settings_.port, settings_.keepalive_s);
  errno_ = errno;
  return rc;
}

int MqttConnection::loop(int timeout_ms) noexcept {
  const int rc = mosquitto_loop(m_, timeout_ms, 1);
  errno_ = errno;
  return rc;
}

int MqttConnection::publish(const std::string& topic, const std::string& payload, int qos, bool retain, int* mid) noexcept {
  return mosquitto_publish(m_, mid, topic.c_str(), static_cast<int>(payload.size()), payload.data(), qos, retain);
}

int MqttConnection::subscribe(const std::string& pattern, int qos) noexcept { return mosquitto_subscribe(m_, nullptr, pattern.c_str(), qos); }

void MqttConnection::disconnect() noexcept { (void)mosquitto_disconnect(m_); }

bool MqttConnection::wants_write() const noexcept { return mosquitto_want_write(m_); }

std::string MqttConnection::error_text(int rc) const {
  std::string s = rc == MOSQ_ERR_ERRNO ? std::strerror(errno_) : mosquitto_strerror(rc);
  while (!s.empty() && s.back() == '.') s.pop_back();  // "...: The connection was lost; retrying"
  return s;
}

std::string MqttConnection::connack_text(int rc) { return mosquitto_connack_string(rc); }

}  // namespace hystlab::lab::detail
