#pragma once
// The config's "lab" section (docs/LAB.md): where this daemon shares what it does with the rest
// of a lab of many rigs. Every run replicated to the lab's PostgreSQL, every rig live over the
// lab's MQTT broker. Both optional; without a "lab" section the daemon keeps everything to its
// own SQLite file, as before.
//
//   "lab": {"name": "materials-lab", "daemon": "frame-pc-2", "url": "http://frame-pc-2:8080/",
//           "postgresql": "postgresql://hystlab@db.lab/hystlab?sslmode=verify-full",
//           "postgresql_password_file": "/etc/hystlab/pg.pass",      (or _env: "HYSTLAB_PG_PASSWORD")
//           "mqtt": {"host": "broker.lab", "port": 8883, "client_id": "...", "username": "...",
//                    "password_file": "...", "ca_file": "...", "live_rate_hz": 20}}
//
// Passwords never sit in the config's JSON: a file or an environment variable names them (a
// password inside the PostgreSQL URL is refused), so that a config can be shared or committed.
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace hystlab::lab {

struct LabConfigError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

struct PostgresTarget {
  std::string conninfo;            // a libpq URL or key=value string, without a password
  std::string password;            // from the file or the environment; empty: libpq's own (~/.pgpass, PGPASSWORD)
  double period_s = 0.5;           // a pass this often when idle: p99 lag 0.55 s during a 1 kHz campaign (bench_replication; 1 s: 1.07 s)
  std::size_t batch_rows = 20000;  // samples per transaction (each with its high-water mark)
};

struct MqttSettings {
  std::string host = "127.0.0.1";
  int port = 1883;
  std::string client_id;  // empty: "hystlabd-<lab>-<daemon>"
  std::string username, password;
  std::string ca_file, cert_file, key_file;  // ca_file set: TLS
  double live_rate_hz = 20;                  // live batches a second per rig
  int keepalive_s = 10;
  std::size_t queue_limit = 2000;  // messages waiting for the broker; beyond, dropped and counted
};

struct LabConfig {
  bool enabled = false;  // a "lab" section was given
  std::string name, daemon;
  std::string url;  // this daemon's page as the lab reaches it ("http://frame-pc-2:8080/"): the lab view links there
  bool has_postgres = false;
  PostgresTarget postgres;
  bool has_mqtt = false;
  MqttSettings mqtt;
};

// Throws LabConfigError naming the field ("config: lab.mqtt.port must be ..."). base_dir: where
// relative password files are read from (the config's folder). env: getenv, replaceable by tests.
[[nodiscard]] LabConfig parse_lab_config(const nlohmann::json& j, const std::string& base_dir, const char* (*env)(const char*) = nullptr);

// A topic or key part: the lab's and daemon's names as MQTT topic levels (no '/', '+', '#').
[[nodiscard]] bool valid_name(const std::string& s) noexcept;

}  // namespace hystlab::lab
