#include "hystlab/lab/mqtt_publisher.hpp"

#include <mosquitto.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <mutex>
#include <thread>

#include "mqtt_connection.hpp"
#include "mqtt_payloads.hpp"
#include "mqtt_records.hpp"

namespace hystlab::lab {
namespace {
using Clock = std::chrono::steady_clock;
using Seconds = std::chrono::duration<double>;

constexpr double kBackoffFirstS = 0.5, kBackoffMaxS = 30;  // reconnection: 0.5 s doubling to 30 s
constexpr double kConnackTimeoutS = 10;                    // a TCP connection without CONNACK is given up after this
constexpr double kStateEveryS = 0.1;                       // supervision snapshots (a change is published within this)
constexpr double kRecordsEveryS = 0.25;                    // the events table, and FOT progress
constexpr std::size_t kWindow = 64;                        // messages in libmosquitto's hands, not yet written (or acked)
constexpr std::size_t kMaxBatch = 1000;                    // samples in one live message
constexpr int kEventsPerRead = 500;
constexpr double kStopFlushS = 2;  // at stop, the wait for "offline" to be acknowledged
}  // namespace

namespace detail {  // named: the publisher's Impl holds them
struct Outgoing {
  std::string topic, payload;
  int qos = 0;
  bool retain = false;
};

struct RigTrack {
  control::RigInfo info;
  std::string topic;  // prefix/<escaped name>
  std::uint64_t pos = 0, seq = 0;
  nlohmann::json state;  // as last seen (without changed_at)
  std::string state_payload;
  bool state_dirty = true;
  std::int64_t nodes = -1;  // the running FOT campaign's nodes (-1: none)
};
}  // namespace detail
using detail::Outgoing;
using detail::RigTrack;

std::string topic_level(std::string_view name) {
  std::string out;
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '%' || c == '/' || c == '+' || c == '#' || u < 0x20 || u == 0x7f) {
      char buf[4];
      std::snprintf(buf, sizeof buf, "%%%02X", static_cast<unsigned>(u));
      out += buf;
    } else {
      out += c;
    }
  }
  return out;
}

std::string topic_prefix(const LabConfig& lab) { return "hystlab/" + topic_level(lab.name) + "/" + topic_level(lab.daemon); }

struct MqttPublisher::Impl final : detail::MqttListener {
  Impl(const control::DaemonInterface& d, LabConfig l, std::string db) : daemon(d), lab(std::move(l)), records(std::move(db)), prefix(topic_prefix(lab)) {}

  const control::DaemonInterface& daemon;
  LabConfig lab;
  detail::RecordReader records;
  std::string prefix, started_at = detail::utc_now();
  std::vector<std::string> rig_names;

  std::thread thread;
  std::atomic<bool> stopping{false};
  std::mutex wake_mu;
  std::condition_variable wake;

  mutable std::mutex status_mu;  // guards st (status() copies it)
  MqttStatus st;

  // The thread's own (libmosquitto's callbacks run on it too, from inside loop()).
  std::unique_ptr<detail::MqttConnection> conn;
  enum class Link { down, connecting, up } link = Link::down;
  Clock::time_point next_attempt{}, connect_deadline{}, next_live{}, next_state{}, next_records{};
  double backoff_s = kBackoffFirstS;
  std::size_t in_flight = 0;
  bool status_dirty = false, events_started = false;
  std::int64_t event_cursor = 0;
  std::deque<Outgoing> live_q, reliable_q;
  std::vector<RigTrack> rigs;

  template <class F>
  void with_status(F&& f) {
    std::lock_guard lk(status_mu);
    f(st);
  }
  void set_error(const std::string& why) {
    with_status([&](MqttStatus& s) { s.last_error = why; });
  }

  // --- libmosquitto's callbacks --------------------------------------------------------------
  void on_connack(int rc) noexcept override {
    try {
      connected(rc);
    } catch (...) {  // only the log line can throw here; the link's state is set before it
    }
  }
  void connected(int rc) {
    if (rc != 0) {  // refused (bad credentials, client id, protocol): the broker closes; retried
      lost("the broker refused the connection: " + detail::MqttConnection::connack_text(rc));
      return;
    }
    link = Link::up;
    backoff_s = kBackoffFirstS;
    in_flight = 0;
    status_dirty = true;                            // the retained status and every rig's state, again: the broker may
    for (RigTrack& r : rigs) r.state_dirty = true;  // have restarted and lost them
    with_status([](MqttStatus& s) {
      s.connected = true;
      if (s.connects++ > 0) ++s.reconnects;
    });
    spdlog::info("mqtt: connected to {}:{} as '{}'", lab.mqtt.host, lab.mqtt.port, lab.mqtt.client_id);
  }
  void on_disconnect(int rc) noexcept override {
    if (rc != 0 && link != Link::down) lost("the connection to the broker was lost: " + conn->error_text(rc));
  }
  void on_published(int) noexcept override {
    if (in_flight > 0) --in_flight;
  }

  // The link is gone (or never came): the next try after the back-off, doubled up to 30 s.
  void lost(const std::string& why) noexcept {
    try {
      const bool was_up = link == Link::up;
      link = Link::down;
      in_flight = 0;
      next_attempt = Clock::now() + std::chrono::duration_cast<Clock::duration>(Seconds(backoff_s));
      with_status([&](MqttStatus& s) {
        s.connected = false;
        s.last_error = why;
      });
      if (was_up) spdlog::warn("mqtt: {}; retrying in {:.1f} s", why, backoff_s);
      backoff_s = std::min(backoff_s * 2, kBackoffMaxS);
    } catch (...) {  // a log line that cannot be written: the state above is what matters
    }
  }

  void try_connect() {
    with_status([](MqttStatus& s) { ++s.connect_attempts; });
    const int rc = conn->connect();
    if (rc != MOSQ_ERR_SUCCESS) {
      lost("cannot connect to " + lab.mqtt.host + ":" + std::to_string(lab.mqtt.port) + ": " + conn->error_text(rc));
      return;
    }
    link = Link::connecting;
    connect_deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(Seconds(kConnackTimeoutS));
  }

  // --- the queue -----------------------------------------------------------------------------
  // Bounded: beyond queue_limit the oldest live batch goes first (a newer one says more), then
  // the oldest event. Retained states never wait here: the newest is published on (re)connect.
  void enqueue(Outgoing m) {
    (m.qos == 0 ? live_q : reliable_q).push_back(std::move(m));
    std::uint64_t dropped = 0;
    while (live_q.size() + reliable_q.size() > lab.mqtt.queue_limit) {
      (live_q.empty() ? reliable_q : live_q).pop_front();
      ++dropped;
    }
    const auto queued = live_q.size() + reliable_q.size();
    with_status([&](MqttStatus& s) {
      s.dropped += dropped;
      s.queued = queued;
    });
  }

  bool send(const Outgoing& m) {
    const int rc = conn->publish(m.topic, m.payload, m.qos, m.retain, nullptr);
    if (rc != MOSQ_ERR_SUCCESS) {
      lost("cannot publish on '" + m.topic + "': " + conn->error_text(rc));
      conn->disconnect();
      return false;
    }
    ++in_flight;
    with_status([](MqttStatus& s) { ++s.published; });
    return true;
  }

  void flush() {
    if (link != Link::up) return;
    if (status_dirty && send({prefix + "/status", status("online", ""), 1, true})) status_dirty = false;
    for (RigTrack& r : rigs)
      if (link == Link::up && r.state_dirty && send({r.topic + "/state", r.state_payload, 1, true})) r.state_dirty = false;
    while (link == Link::up && in_flight < kWindow && !(reliable_q.empty() && live_q.empty())) {
      auto& q = reliable_q.empty() ? live_q : reliable_q;
      if (!send(q.front())) break;
      q.pop_front();
    }
    const auto queued = live_q.size() + reliable_q.size();
    with_status([&](MqttStatus& s) { s.queued = queued; });
  }

  [[nodiscard]] std::string status(const std::string& state, const std::string& reason) const {
    return detail::status_json(lab, state, started_at, reason, rig_names);
  }

  // --- what is read from the daemon ------------------------------------------------------------
  void read_states() {
    for (std::size_t k = 0; k < rigs.size(); ++k) {
      RigTrack& r = rigs[k];
      const control::AcquisitionCounters a = daemon.rig_counters(k);
      nlohmann::json j = detail::state_json(r.info, daemon.rig_supervision(k), a, a.campaign != 0 ? r.nodes : -1);
      if (j == r.state) continue;
      r.state = j;
      j["changed_at"] = detail::utc_now();
      r.state_payload = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
      r.state_dirty = true;
    }
  }

  // Every sample since the last batch, none skipped: split where the run changes and at
  // kMaxBatch; samples the ring overwrote before they were read are counted in "lost".
  void read_live() {
    std::vector<control::LiveSample> got;
    for (std::size_t k = 0; k < rigs.size(); ++k) {
      RigTrack& r = rigs[k];
      got.clear();
      std::uint64_t lost_n = 0;
      const std::uint64_t next = daemon.read_live(k, r.pos, 1, got, &lost_n);
      std::uint64_t index = next - got.size();
      r.pos = next;
      if (lost_n > 0) with_status([&](MqttStatus& s) { s.lost_samples += lost_n; });
      std::size_t i = 0;
      while (i < got.size()) {
        detail::LiveBatch b;
        b.seq = ++r.seq, b.first = index, b.run = got[i].run, b.lost = lost_n;
        lost_n = 0;
        while (i < got.size() && got[i].run == b.run && b.samples.size() < kMaxBatch) b.samples.push_back(got[i++]);
        index += b.samples.size();
        enqueue({r.topic + "/live", detail::live_json(r.info.name, r.info.kind, b), 0, false});
      }
    }
  }

  void read_records() {
    if (!events_started) {  // from the newest at start-up: the history is in the daemon's API
      event_cursor = records.newest_event();
      events_started = true;
    }
    for (const detail::EventRow& e : records.events_after(event_cursor, kEventsPerRead)) {
      event_cursor = e.id;
      std::string topic = prefix + "/event";  // a row of no rig's campaign: the daemon's own topic
      for (const RigTrack& r : rigs)
        if (r.info.name == e.rig) topic = r.topic + "/event";
      enqueue({topic, detail::event_json(e), 1, false});
    }
    for (std::size_t k = 0; k < rigs.size(); ++k) {
      const std::int64_t campaign = daemon.rig_counters(k).campaign;
      rigs[k].nodes = campaign != 0 ? records.fot_nodes(campaign) : -1;
    }
  }

  void run() noexcept;
  void step();
  void wait_or_loop(Clock::time_point until);
  void say_offline() noexcept;
};

// One pass: read what is due, hand what waits to the connection, then network I/O (or a wait)
// until the next thing is due.
void MqttPublisher::Impl::step() {
  const auto now = Clock::now();
  if (link == Link::down && now >= next_attempt) try_connect();
  if (link == Link::connecting && now >= connect_deadline) {
    lost("no answer (CONNACK) from " + lab.mqtt.host + ":" + std::to_string(lab.mqtt.port) + " within 10 s");
    conn->disconnect();
  }
  auto period = [](double s) { return std::chrono::duration_cast<Clock::duration>(Seconds(s)); };
  if (now >= next_state) {
    read_states();
    next_state = now + period(kStateEveryS);
  }
  if (now >= next_live) {
    read_live();
    next_live += period(1.0 / lab.mqtt.live_rate_hz);
    if (next_live < now) next_live = now + period(1.0 / lab.mqtt.live_rate_hz);  // fell behind: no burst
  }
  if (now >= next_records) {
    try {
      read_records();
    } catch (const std::exception& e) {  // the file busy or not yet made: tried again next time
      records.reset();
      set_error(std::string("events: ") + e.what());
    }
    next_records = now + period(kRecordsEveryS);
  }
  flush();
  wait_or_loop(std::min({next_state, next_live, next_records, now + period(0.05)}));
}

void MqttPublisher::Impl::wait_or_loop(Clock::time_point until) {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now()).count();
  const int timeout = static_cast<int>(std::clamp<long long>(ms, 1, 100));
  if (link == Link::down) {  // no socket to wait on: sleep, but wake for stop()
    std::unique_lock lk(wake_mu);
    wake.wait_for(lk, std::chrono::milliseconds(timeout), [this] { return stopping.load(); });
    return;
  }
  const int rc = conn->loop(timeout);
  if (rc != MOSQ_ERR_SUCCESS && link != Link::down) lost("the connection to the broker was lost: " + conn->error_text(rc));
}

// A clean stop: "offline" retained, acknowledged (or given up after kStopFlushS), then
// DISCONNECT, after which the broker does not publish the will.
void MqttPublisher::Impl::say_offline() noexcept {
  try {
    if (link != Link::up) return;  // the broker published the will already, or never had one
    if (!send({prefix + "/status", status("offline", "stopped"), 1, true})) return;
    const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(Seconds(kStopFlushS));
    // Everything handed before "offline" is acknowledged with it (in order, on one connection).
    while (link == Link::up && in_flight > 0 && Clock::now() < until) wait_or_loop(until);
    conn->disconnect();
    for (int k = 0; k < 10 && conn->wants_write(); ++k) (void)conn->loop(10);
  } catch (...) {
  }
}

void MqttPublisher::Impl::run() noexcept {
  daemon.keep_off_acquisition_cpu(true);  // long-lived, low-priority work: not on the rigs' CPU
  while (!stopping) {
    try {
      step();
    } catch (const std::exception& e) {  // never out of the thread: the reason becomes the status
      try {
        set_error(std::string("publisher: ") + e.what());
        spdlog::error("mqtt: {}", e.what());
      } catch (...) {
      }
      std::unique_lock lk(wake_mu);
      wake.wait_for(lk, std::chrono::seconds(1), [this] { return stopping.load(); });
    } catch (...) {
      set_error("publisher: an unknown error");
    }
  }
  say_offline();
  link = Link::down;  // a later start() connects afresh
  try {
    with_status([](MqttStatus& s) { s.connected = false; });
  } catch (...) {
  }
}

MqttPublisher::MqttPublisher(const control::DaemonInterface& daemon, LabConfig lab, std::string events_db)
    : impl_(std::make_unique<Impl>(daemon, std::move(lab), std::move(events_db))) {}

MqttPublisher::~MqttPublisher() { stop(); }

void MqttPublisher::start() {
  Impl& m = *impl_;
  if (m.thread.joinable()) return;
  m.rigs.clear();
  m.rig_names.clear();
  for (std::size_t k = 0; k < m.daemon.rig_count(); ++k) {
    RigTrack r;
    r.info = m.daemon.rig_info(k);
    r.topic = m.prefix + "/" + topic_level(r.info.name);
    r.pos = m.daemon.live_head(k);  // live from now on: the past is in the daemon's database
    m.rig_names.push_back(r.info.name);
    m.rigs.push_back(std::move(r));
  }
  m.conn = std::make_unique<detail::MqttConnection>(m.lab.mqtt, m.prefix + "/status", m.status("offline", "connection lost (the broker's will)"), m);
  m.stopping = false;
  m.with_status([](MqttStatus& s) { s.running = true; });
  m.thread = std::thread([&m] { m.run(); });
}

void MqttPublisher::stop() noexcept {
  Impl& m = *impl_;
  if (!m.thread.joinable()) return;
  {
    std::lock_guard lk(m.wake_mu);
    m.stopping = true;
  }
  m.wake.notify_all();
  m.thread.join();
  m.with_status([](MqttStatus& s) { s.running = false; });
}

MqttStatus MqttPublisher::status() const {
  std::lock_guard lk(impl_->status_mu);
  return impl_->st;
}

}  // namespace hystlab::lab

namespace hystlab::lab {
control::MqttCounters counters_of(const MqttStatus& s) {
  control::MqttCounters c;
  c.configured = s.running;
  c.connected = s.connected;
  if (!s.connected) c.error = s.last_error;  // the reason it is not connected; an old one once it is
  c.published = s.published;
  c.dropped = s.dropped;
  c.reconnects = s.reconnects;
  return c;
}
}  // namespace hystlab::lab
