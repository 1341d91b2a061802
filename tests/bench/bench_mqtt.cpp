// Every rig live over MQTT (issue 26): the latency from a sample's acquisition to its arrival at
// an MQTT subscriber, through hystlab::lab::MqttPublisher, Debian's mosquitto on loopback and a
// libmosquitto subscriber in this process (both ends read the machine's steady clock: each
// sample's mono_s against the arrival). The daemon is the tests' fake, feeding one rig at 1 kHz
// (tests/lab/fake_daemon.hpp): what is measured is the publisher's batching (live_rate_hz, 20 a
// second: a sample waits up to 50 ms for its batch) and the broker's hop, not a rig's link.
// Prints p50, p99 and max for every sample and for each batch's newest sample (the transport's
// own share), and checks that every batch arrived in order with no sample skipped.
#include <mosquitto.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "../lab/fake_daemon.hpp"
#include "../support/mosquitto_broker.hpp"
#include "hystlab/db/store.hpp"
#include "hystlab/lab/mqtt_publisher.hpp"

namespace {
using hystlab::test_support::wait_until;

double mono_now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

struct Received {
  std::mutex mu;
  std::vector<double> every_ms, newest_ms;
  std::uint64_t batches = 0, gaps = 0, next_first = 0, next_seq = 0;
};

void on_message(mosquitto*, void* obj, const mosquitto_message* m) {
  const double now = mono_now();
  auto& r = *static_cast<Received*>(obj);
  const auto b = nlohmann::json::parse(static_cast<const char*>(m->payload), static_cast<const char*>(m->payload) + m->payloadlen);
  std::lock_guard lk(r.mu);
  const auto first = b["first"].get<std::uint64_t>(), seq = b["seq"].get<std::uint64_t>();
  if (r.batches > 0 && (first != r.next_first || seq != r.next_seq || b["lost"] != 0)) ++r.gaps;
  ++r.batches;
  r.next_first = first + b["samples"].size(), r.next_seq = seq + 1;
  for (const auto& s : b["samples"]) r.every_ms.push_back((now - s[1].get<double>()) * 1000);
  if (!b["samples"].empty()) r.newest_ms.push_back((now - b["samples"].back()[1].get<double>()) * 1000);
}

double pct(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}
}  // namespace

int main(int argc, char** argv) {
  double seconds = argc > 2 && std::string(argv[1]) == "--seconds" ? std::atof(argv[2]) : 10;
  hystlab::test_support::TempDir dir("bench-mqtt");
  const std::string db = (dir / "lab.db").string();
  { hystlab::db::Store s(db); }
  hystlab::test_support::MosquittoBroker broker;
  hystlab::test_support::FakeDaemon fake({"frame 1"}, db);
  hystlab::lab::LabConfig cfg;
  cfg.enabled = cfg.has_mqtt = true;
  cfg.name = "bench", cfg.daemon = "pc";
  cfg.mqtt.port = broker.port(), cfg.mqtt.client_id = "hystlabd-bench";
  hystlab::lab::MqttPublisher pub(fake, cfg, db);

  Received got;
  mosquitto_lib_init();
  mosquitto* sub = mosquitto_new("bench-subscriber", true, &got);
  mosquitto_message_callback_set(sub, on_message);
  if (mosquitto_connect(sub, "127.0.0.1", broker.port(), 10) != MOSQ_ERR_SUCCESS ||
      mosquitto_subscribe(sub, nullptr, "hystlab/bench/pc/frame 1/live", 0) != 0 || mosquitto_loop_start(sub) != MOSQ_ERR_SUCCESS) {
    std::fprintf(stderr, "bench_mqtt: the subscriber cannot connect to the broker\n");
    return 1;
  }
  pub.start();
  if (!wait_until([&] { return pub.status().connected; }, 10)) {
    std::fprintf(stderr, "bench_mqtt: the publisher did not connect: %s\n", pub.status().last_error.c_str());
    return 1;
  }
  fake.set_state("running", false, 1, 1);
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));  // the measured stretch
  pub.stop();
  mosquitto_disconnect(sub);
  mosquitto_loop_stop(sub, false);
  mosquitto_destroy(sub);

  std::lock_guard lk(got.mu);
  const auto st = pub.status();
  std::printf("MQTT live, 1 kHz, %.0f batches/s, %.0f s: %llu batches, %zu samples, %llu out of order or skipped, %llu dropped\n", cfg.mqtt.live_rate_hz,
              seconds, static_cast<unsigned long long>(got.batches), got.every_ms.size(), static_cast<unsigned long long>(got.gaps),
              static_cast<unsigned long long>(st.dropped));
  std::printf("  sample -> subscriber:        p50 %6.1f ms  p99 %6.1f ms  max %6.1f ms\n", pct(got.every_ms, 0.5), pct(got.every_ms, 0.99),
              pct(got.every_ms, 1.0));
  std::printf("  batch's newest -> subscriber: p50 %6.1f ms  p99 %6.1f ms  max %6.1f ms\n", pct(got.newest_ms, 0.5), pct(got.newest_ms, 0.99),
              pct(got.newest_ms, 1.0));
  return got.gaps == 0 && got.batches > 0 ? 0 : 1;
}
