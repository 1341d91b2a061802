#pragma once
// Every rig live over the lab's MQTT broker (docs/LAB.md, "Every rig live over MQTT"): each rig's
// supervision state (retained), its live samples in batches, its campaign's events, and this
// daemon's online/offline status (its will). Read-only by design: the publisher subscribes to
// nothing, so nothing a broker or another client sends can move a rig.
//
// One thread of its own reads the daemon through control::DaemonInterface (wait-free live rings,
// snapshots) and the events table of the daemon's SQLite file, and drives libmosquitto's network
// loop itself: a broker down, slow or unreachable costs the acquisition nothing. Messages wait in
// a bounded queue (MqttSettings::queue_limit, the oldest live batch dropped first and counted);
// reconnection backs off from 0.5 s doubling to 30 s; the retained state and status are published
// again on every (re)connection.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "hystlab/control/daemon_interface.hpp"
#include "hystlab/lab/lab_config.hpp"

namespace hystlab::lab {

// What the publisher has done, a copy (for /api/status and /metrics).
struct MqttStatus {
  bool running = false;                // start() called, stop() not yet
  bool connected = false;              // the broker acknowledged the connection (CONNACK accepted)
  std::uint64_t published = 0;         // messages handed to the broker's connection
  std::uint64_t dropped = 0;           // messages dropped from the full queue (never sent)
  std::uint64_t connects = 0;          // connections accepted by the broker, the first included
  std::uint64_t reconnects = 0;        // of those, after the first (the broker came back)
  std::uint64_t connect_attempts = 0;  // every try, failed ones included
  std::uint64_t lost_samples = 0;      // live samples the rig's ring overwrote before they were read
  std::uint64_t queued = 0;            // messages waiting now
  std::string last_error;              // the newest failure in words ("" when none yet)
};

// The counters /api/status and /metrics show (control::LabCounters).
[[nodiscard]] control::MqttCounters counters_of(const MqttStatus& s);

// A rig's name as one MQTT topic level: '%', '/', '+', '#' and control characters become %XX
// (upper-case hex, as in a URL); everything else, spaces and UTF-8 included, stays as is.
[[nodiscard]] std::string topic_level(std::string_view name);
// "hystlab/<lab>/<daemon>": every topic of this daemon starts so.
[[nodiscard]] std::string topic_prefix(const LabConfig& lab);

class MqttPublisher {
 public:
  // daemon must outlive the publisher. events_db: the daemon's SQLite file (its events table).
  MqttPublisher(const control::DaemonInterface& daemon, LabConfig lab, std::string events_db);
  ~MqttPublisher();  // stop()
  MqttPublisher(const MqttPublisher&) = delete;
  MqttPublisher& operator=(const MqttPublisher&) = delete;

  // Starts the thread and returns at once: the broker need not be reachable (the thread keeps
  // trying). Throws std::runtime_error only when libmosquitto refuses the settings (a TLS file
  // it cannot use, say), naming the field.
  void start();
  // Publishes "offline" (retained), disconnects and joins the thread; bounded (about 2 s at
  // most with a broker that does not answer). Idempotent.
  void stop() noexcept;

  [[nodiscard]] MqttStatus status() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hystlab::lab
