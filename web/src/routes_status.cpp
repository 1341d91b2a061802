// Daemon status, rigs with their live sample and I/O health, and /metrics (Prometheus text).
#include <chrono>
#include <map>
#include <mutex>
#include <vector>

#include "hystlab/domain/signals.hpp"
#include "hystlab/protocols/signals.hpp"
#include "request_guard.hpp"
#include "routes.hpp"

namespace hystlab::web {
namespace {
std::map<std::string, std::int64_t> campaigns_by_state(db::Reads& store) {
  std::map<std::string, std::int64_t> out;
  for (const domain::CampaignState s : domain::kCampaignStates) out[domain::to_string(s)] = 0;
  for (const auto& [state, n] : store.campaign_counts()) out[domain::to_string(state)] = n;
  return out;
}

json health_json(const control::LinkHealth& h) {
  json errors = json::object();
  for (const auto& [kind, n] : h.errors) errors[kind] = n;
  return {{"reads", h.reads},
          {"writes", h.writes},
          {"reconnects", h.reconnects},
          {"lost_samples", h.lost_samples},
          {"errors", errors},
          {"last_transaction_us", h.last_transaction_us},
          {"max_transaction_us", h.max_transaction_us},
          {"latency_histogram_us", h.latency_histogram_us}};
}

// A rig by its id or its name.
std::size_t rig_of(ApiContext& c, const std::string& key) {
  for (std::size_t k = 0; k < c.daemon.rig_count(); ++k)
    if (c.daemon.rig_info(k).name == key || std::to_string(c.daemon.rig_info(k).id) == key) return k;
  throw ApiError(404, "not found", "no rig '" + key + "'");
}

// Label values escaped as the exposition format asks.
std::string label(const std::string& v) {
  std::string o;
  for (char ch : v) {
    if (ch == '\\' || ch == '"') o += '\\';
    if (ch == '\n') {
      o += "\\n";
      continue;
    }
    o += ch;
  }
  return o;
}

void metric(std::string& out, const char* name, const char* type, const char* help) {
  out += std::string("# HELP ") + name + " " + help + "\n# TYPE " + name + " " + type + "\n";
}

void lab_metrics(std::string& o, const control::LabCounters& l);

std::string metrics_text(ApiContext& c) {
  const control::DaemonInterface& d = c.daemon;
  std::string o;
  auto line = [&o](const std::string& name, const std::string& labels, double v) {
    o += name + (labels.empty() ? "" : "{" + labels + "}") + " " + json(v).dump() + "\n";
  };
  const control::WriterCounters w = d.writer();
  metric(o, "hystlab_samples_written_total", "counter", "Samples committed to the database.");
  line("hystlab_samples_written_total", "", static_cast<double>(w.written));
  metric(o, "hystlab_writer_queue_depth", "gauge", "Samples waiting for the writer thread.");
  line("hystlab_writer_queue_depth", "", static_cast<double>(w.depth));
  metric(o, "hystlab_writer_dropped_total", "counter", "Samples lost because the writer queue was full.");
  line("hystlab_writer_dropped_total", "", static_cast<double>(w.dropped));
  metric(o, "hystlab_writer_commits_total", "counter", "Write transactions committed.");
  line("hystlab_writer_commits_total", "", static_cast<double>(w.commits));
  metric(o, "hystlab_samples_acquired_total", "counter", "Samples acquired during campaigns.");
  for (std::size_t k = 0; k < d.rig_count(); ++k)
    line("hystlab_samples_acquired_total", "rig=\"" + label(d.rig_info(k).name) + "\"", static_cast<double>(d.rig_counters(k).samples));
  metric(o, "hystlab_missed_deadlines_total", "counter", "Samples not taken in time: late periods when polling, lost samples with block reads.");
  for (std::size_t k = 0; k < d.rig_count(); ++k)
    line("hystlab_missed_deadlines_total", "rig=\"" + label(d.rig_info(k).name) + "\"", static_cast<double>(d.rig_counters(k).missed_deadlines));
  metric(o, "hystlab_late_wakeups_total", "counter", "Acquisition periods that started more than a period late.");
  for (std::size_t k = 0; k < d.rig_count(); ++k)
    line("hystlab_late_wakeups_total", "rig=\"" + label(d.rig_info(k).name) + "\"", static_cast<double>(d.rig_counters(k).late_wakeups));
  metric(o, "hystlab_submission_latency_seconds", "gauge", "The newest submission's time from the call to its rig's thread taking the job.");
  for (std::size_t k = 0; k < d.rig_count(); ++k)
    if (const double s = d.rig_counters(k).submit_latency_s; s >= 0) line("hystlab_submission_latency_seconds", "rig=\"" + label(d.rig_info(k).name) + "\"", s);
  std::vector<std::pair<std::string, control::LinkHealth>> rigs;  // one read per rig: families stay consistent
  for (std::size_t k = 0; k < d.rig_count(); ++k) rigs.emplace_back("rig=\"" + label(d.rig_info(k).name) + "\"", d.rig_health(k));
  auto family = [&](const char* name, const char* type, const char* help, auto value) {
    metric(o, name, type, help);
    for (const auto& [rl, h] : rigs) line(name, rl, static_cast<double>(value(h)));
  };
  family("hystlab_rig_reads_total", "counter", "Rig read transactions.", [](const auto& h) { return h.reads; });
  family("hystlab_rig_writes_total", "counter", "Rig write transactions.", [](const auto& h) { return h.writes; });
  family("hystlab_rig_reconnects_total", "counter", "Rig reconnections.", [](const auto& h) { return h.reconnects; });
  family("hystlab_rig_lost_samples_total", "counter", "Samples a controller's buffer lost before a block read.", [](const auto& h) { return h.lost_samples; });
  family("hystlab_rig_transaction_max_seconds", "gauge", "Longest rig transaction.", [](const auto& h) { return h.max_transaction_us * 1e-6; });
  metric(o, "hystlab_rig_errors_total", "counter", "Rig I/O errors by kind.");
  for (const auto& [rl, h] : rigs)
    for (const auto& [kind, n] : h.errors) line("hystlab_rig_errors_total", rl + ",kind=\"" + kind + "\"", static_cast<double>(n));
  metric(o, "hystlab_rig_transaction_seconds", "histogram", "Rig transaction time.");
  for (const auto& [rl, h] : rigs) {
    std::uint64_t cum = 0;
    const std::size_t buckets = h.latency_histogram_us.size();
    for (std::size_t b = 0; b < buckets; ++b) {
      cum += h.latency_histogram_us[b];
      const std::string le = b + 1 == buckets ? "+Inf" : json(static_cast<double>(1ULL << (b + 1)) * 1e-6).dump();
      line("hystlab_rig_transaction_seconds_bucket", rl + ",le=\"" + le + "\"", static_cast<double>(cum));
    }
    line("hystlab_rig_transaction_seconds_sum", rl, h.total_transaction_us * 1e-6);
    line("hystlab_rig_transaction_seconds_count", rl, static_cast<double>(cum));
  }
  metric(o, "hystlab_sse_clients", "gauge", "Open Server-Sent Events streams.");
  line("hystlab_sse_clients", "", c.stream_clients.load());
  metric(o, "hystlab_http_requests_total", "counter", "HTTP requests answered.");
  line("hystlab_http_requests_total", "", static_cast<double>(c.requests.load()));
  metric(o, "hystlab_campaigns", "gauge", "Campaigns by state.");
  for (const auto& [state, n] : campaigns_by_state(reader(c.db_path))) line("hystlab_campaigns", "state=\"" + state + "\"", static_cast<double>(n));
  metric(o, "hystlab_rig_state", "gauge", "The rig supervisor's state (1 for the current one).");
  for (std::size_t k = 0; k < d.rig_count(); ++k) {
    const auto sv = d.rig_supervision(k);
    for (const char* st : {"disconnected", "idle", "arming", "armed", "holding", "estopped", "faulted", "safing"})
      line("hystlab_rig_state", "rig=\"" + label(d.rig_info(k).name) + "\",state=\"" + st + "\"", sv.state == st ? 1.0 : 0.0);
  }
  metric(o, "hystlab_rig_latched", "gauge", "1 while an e-stop or a fault is latched (nothing arms until a reset).");
  for (std::size_t k = 0; k < d.rig_count(); ++k)
    line("hystlab_rig_latched", "rig=\"" + label(d.rig_info(k).name) + "\"", d.rig_supervision(k).latched ? 1.0 : 0.0);
  metric(o, "hystlab_rig_transitions_total", "counter", "Rig supervisor state transitions.");
  for (std::size_t k = 0; k < d.rig_count(); ++k)
    line("hystlab_rig_transitions_total", "rig=\"" + label(d.rig_info(k).name) + "\"", static_cast<double>(d.rig_supervision(k).transitions));
  metric(o, "hystlab_rig_link_losses_total", "counter", "Times the link to the rig was lost.");
  for (std::size_t k = 0; k < d.rig_count(); ++k)
    line("hystlab_rig_link_losses_total", "rig=\"" + label(d.rig_info(k).name) + "\"", static_cast<double>(d.rig_supervision(k).link_losses));
  metric(o, "hystlab_uptime_seconds", "gauge", "Seconds since the daemon started.");
  line("hystlab_uptime_seconds", "", d.uptime_s());
  if (c.lab) lab_metrics(o, c.lab());
  return o;
}

// The lab section of /api/status (docs/LAB.md): replication's backlog and lag, MQTT's link.
json lab_json(const control::LabCounters& l) {
  const control::ReplicationCounters& r = l.replication;
  const control::MqttCounters& m = l.mqtt;
  auto err = [](const std::string& e) { return e.empty() ? json(nullptr) : json(e); };
  return {
      {"name", l.lab},
      {"daemon", l.daemon},
      {"postgresql", r.configured ? json{{"connected", r.connected},
                                         {"error", err(r.error)},
                                         {"backlog_samples", r.backlog_samples},
                                         {"lag_s", r.lag_s},
                                         {"samples", r.samples},
                                         {"rows", r.rows},
                                         {"passes", r.passes},
                                         {"failures", r.failures}}
                                  : json(nullptr)},
      {"mqtt", m.configured
                   ? json{{"connected", m.connected}, {"error", err(m.error)}, {"published", m.published}, {"dropped", m.dropped}, {"reconnects", m.reconnects}}
                   : json(nullptr)}};
}

void lab_metrics(std::string& o, const control::LabCounters& l) {
  auto line = [&o](const char* name, const char* type, const char* help, const json& v) {
    metric(o, name, type, help);
    o += std::string(name) + " " + json(v).dump() + "\n";
  };
  if (l.replication.configured) {
    const control::ReplicationCounters& r = l.replication;
    line("hystlab_replication_connected", "gauge", "1 while the lab's PostgreSQL takes this daemon's rows.", json(r.connected ? 1 : 0));
    line("hystlab_replication_backlog_samples", "gauge", "Samples in SQLite not yet in the lab's PostgreSQL.", json(r.backlog_samples));
    line("hystlab_replication_lag_seconds", "gauge", "Everything SQLite held this long ago is in the lab's PostgreSQL.", r.lag_s);
    line("hystlab_replication_samples_total", "counter", "Samples copied to the lab's PostgreSQL since start.", json(r.samples));
    line("hystlab_replication_rows_total", "counter", "Rows of every table copied to the lab's PostgreSQL since start.", json(r.rows));
    line("hystlab_replication_failures_total", "counter", "Replication passes that failed (the reason: /api/status).", json(r.failures));
  }
  if (l.mqtt.configured) {
    const control::MqttCounters& m = l.mqtt;
    line("hystlab_mqtt_connected", "gauge", "1 while the lab's MQTT broker is connected.", json(m.connected ? 1 : 0));
    line("hystlab_mqtt_published_total", "counter", "MQTT messages handed to the broker.", json(m.published));
    line("hystlab_mqtt_dropped_total", "counter", "MQTT messages dropped (broker down or slow, queue full).", json(m.dropped));
    line("hystlab_mqtt_reconnects_total", "counter", "Reconnections to the MQTT broker.", json(m.reconnects));
  }
}

// /api/status is what monitors poll: served from a snapshot at most 0.25 s old.
struct StatusCache {
  std::mutex mu;
  std::string body;
  std::chrono::steady_clock::time_point at{};
};
}  // namespace

json rig_json(const control::DaemonInterface& d, std::size_t k) {
  const control::RigInfo info = d.rig_info(k);
  const control::AcquisitionCounters live = d.rig_counters(k);
  json j{{"id", info.id},
         {"index", k},
         {"name", info.name},
         {"kind", domain::to_string(info.kind)},
         {"description", info.description},
         {"simulated", info.simulated},
         {"campaign", live.campaign},
         {"phase", live.phase},
         {"samples", live.samples},
         {"missed_deadlines", live.missed_deadlines},
         {"late_wakeups", live.late_wakeups},
         {"health", health_json(d.rig_health(k))},
         {"sample", nullptr}};
  const control::RigSupervision sv = d.rig_supervision(k);
  j["state"] = sv.state;
  j["latched"] = sv.latched;
  j["latch_reason"] = sv.latch_reason.empty() ? json(nullptr) : json(sv.latch_reason);
  j["fault"] = sv.fault_code == 0 && sv.latched_fault_code == 0
                   ? json(nullptr)
                   : json{{"code", sv.fault_code ? sv.fault_code : sv.latched_fault_code}, {"text", sv.fault_text}};
  const unsigned w = sv.status_word;
  namespace stb = protocols::status;
  j["status"] = {{"word", w},
                 {"ready", (w & stb::ready) != 0},
                 {"enabled", (w & stb::enabled) != 0},
                 {"holding", (w & stb::holding) != 0},
                 {"estop", (w & stb::estop) != 0},
                 {"limit_tripped", (w & stb::limit_tripped) != 0},
                 {"fault", (w & stb::fault) != 0},
                 {"moving", (w & stb::moving) != 0},
                 {"known", sv.have_sample}};
  j["resetting"] = sv.resetting;
  j["reset_refusal"] = sv.reset_refusal.empty() ? json(nullptr) : json(sv.reset_refusal);
  j["recovering"] = sv.recovering;
  j["recovery_result"] = sv.recovery_result.empty() ? json(nullptr) : json(sv.recovery_result);
  // A load frame latched beyond its stroke (a reset cannot clear it), or idle outside the
  // configured stroke: POST .../recover brings it back.
  const json& stroke = sv.envelope.is_object() ? sv.envelope.value("stroke_mm", json()) : json();
  const bool outside = stroke.is_array() && stroke.size() == 2 && (sv.position_mm < stroke[0].get<double>() || sv.position_mm > stroke[1].get<double>());
  j["recoverable"] = info.kind != domain::RigKind::shaker && sv.have_sample && !sv.recovering &&
                     ((sv.latched && (w & stb::limit_tripped) != 0) || (!sv.latched && sv.state == "idle" && outside));
  j["link_losses"] = sv.link_losses;
  j["transitions"] = sv.recent;
  j["envelope"] = sv.envelope;
  j["supervision"] = sv.supervision;
  const std::uint64_t h = d.live_head(k);
  std::vector<control::LiveSample> last;
  if (h > 0) (void)d.read_live(k, h - 1, 1, last);
  if (!last.empty()) {
    const control::LiveSample& s = last.back();
    const auto& n = domain::live_signals(info.kind);
    j["sample"] = {{"t", s.t}, {n[0], s.v[0]}, {n[1], s.v[1]}, {n[2], s.v[2]}, {"status", s.status}, {"run", s.run}};
  }
  return j;
}

void add_status_routes(httplib::Server& s, ApiContext& c) {
  auto cache = std::make_shared<StatusCache>();
  s.Get(
      "/api/status", guarded([&c, cache](const httplib::Request&, httplib::Response& res) {
        std::lock_guard lk(cache->mu);
        const auto now = std::chrono::steady_clock::now();
        if (cache->body.empty() || now - cache->at > std::chrono::milliseconds(250)) {
          json rigs = json::array();
          for (std::size_t k = 0; k < c.daemon.rig_count(); ++k)
            rigs.push_back(
                {{"name", c.daemon.rig_info(k).name}, {"kind", domain::to_string(c.daemon.rig_info(k).kind)}, {"campaign", c.daemon.rig_counters(k).campaign}});
          const control::WriterCounters w = c.daemon.writer();
          cache->body = json{{"name", "hystlabd"},
                             {"version", HYSTLAB_VERSION},
                             {"uptime_s", c.daemon.uptime_s()},
                             {"database", c.db_path},
                             {"rigs", rigs},
                             {"campaigns", campaigns_by_state(reader(c.db_path))},
                             {"writer", {{"written", w.written}, {"queue_depth", w.depth}, {"dropped", w.dropped}}},
                             {"stream_clients", c.stream_clients.load()},
                             {"lab", c.lab ? lab_json(c.lab()) : json(nullptr)}}
                            .dump();
          cache->at = now;
        }
        res.set_content(cache->body, "application/json");
      }));
  s.Get("/api/rigs", guarded([&c](const httplib::Request&, httplib::Response& res) {
          json out = json::array();
          for (std::size_t k = 0; k < c.daemon.rig_count(); ++k) out.push_back(rig_json(c.daemon, k));
          send_json(res, out);
        }));
  s.Get(R"(/api/rigs/([^/]+))",
        guarded([&c](const httplib::Request& req, httplib::Response& res) { send_json(res, rig_json(c.daemon, rig_of(c, req.matches[1].str()))); }));
  // The operator's e-stop and reset: straight to the rig's thread, whatever runs (or nothing).
  // recover: a load frame latched beyond its stroke, brought back into it at the safe rate.
  post_route(s, c, R"(/api/rigs/([^/]+)/(reset|estop|recover))", guarded([&c](const httplib::Request& req, httplib::Response& res) {
               const std::size_t k = rig_of(c, req.matches[1].str());
               const std::string verb = req.matches[2].str();
               const control::RigCommand command = verb == "reset"   ? control::RigCommand::reset
                                                   : verb == "estop" ? control::RigCommand::estop
                                                                     : control::RigCommand::recover;
               const control::CommandOutcome o = c.daemon.rig_command(k, command);
               send_outcome(res, json{{"rig", c.daemon.rig_info(k).name}, {"command", verb}}, o);
             }));
  s.Get("/metrics", guarded([&c](const httplib::Request&, httplib::Response& res) { res.set_content(metrics_text(c), "text/plain; version=0.0.4"); }));
}

}  // namespace hystlab::web
