#include "event_stream.hpp"

#include <chrono>
#include <cstdio>
#include <memory>
#include <thread>

#include "hystlab/db/sqlite.hpp"
#include "hystlab/domain/signals.hpp"
#include "routes.hpp"

namespace hystlab::web {
namespace {
constexpr auto kTick = std::chrono::milliseconds(50);  // samples leave at most this long after acquisition
constexpr int kRecordEvery = 4;                        // ticks between checks for new records (200 ms)
constexpr int kRecordPollAnyway = 40;                  // ticks between reads even when nothing moved here (2 s):
                                                       // another process (the CLI) may have written
constexpr int kKeepAliveEvery = 300;                   // ticks between comments on a quiet stream (15 s)

struct StreamState {
  StreamCursor cursor;
  std::vector<std::uint64_t> ring_pos;  // per rig
  std::vector<std::size_t> rigs;        // which rigs
  double rate_hz = 20;
  int tick = 0, quiet = 0, since_read = 0;
  std::uint64_t seen_generation = ~0ULL;
  bool hello_sent = false;
};

StreamCursor newest(db::Reads& store) { return {store.newest_id("events"), store.newest_id("fot_nodes"), store.newest_id("tables")}; }

std::string frame(const std::string& type, const json& data, const std::string& id = {}) {
  std::string f = id.empty() ? "" : "id: " + id + "\n";
  return f + "event: " + type + "\ndata: " + data.dump(-1, ' ', false, json::error_handler_t::replace) + "\n\n";
}

// Records stored since the cursor, as frames; advances the cursor.
std::string records(db::Reads& store, StreamCursor& cur) {
  std::string out;
  for (const db::EventInfo& e : store.events_after(cur.event, 500)) {
    cur.event = e.id;
    json j{{"id", e.id}, {"campaign", e.campaign}, {"at", e.at}, {"kind", e.kind}, {"detail", e.detail.empty() ? json("") : event_detail(e.kind, e.detail)}};
    if (e.kind == "state") {
      j["from"] = e.from_state, j["to"] = e.to_state;
      const auto to = domain::campaign_state_from(e.to_state);
      j["active"] = to && domain::is_active(*to);
      j["final"] = to && domain::is_final(*to);
    }
    out += frame(e.kind == "state" ? "campaign" : e.kind, j, cur.id());
  }
  for (const db::NodeInfo& n : store.nodes_after(cur.node, 2000)) {
    cur.node = n.id;
    out += frame("node", node_json(n), cur.id());
  }
  for (const db::TableInfo& t : store.tables_after(cur.table, 100)) {
    cur.table = t.id;
    out += frame("table", table_json(t), cur.id());
  }
  return out;
}

// New live samples of each rig, one frame per rig, every stride-th sample.
std::string samples(const control::DaemonInterface& d, StreamState& st) {
  std::string out;
  std::vector<control::LiveSample> got;
  for (std::size_t k = 0; k < st.rigs.size(); ++k) {
    const control::AcquisitionCounters live = d.rig_counters(st.rigs[k]);
    const double rig_rate = live.campaign != 0 ? live.sample_rate_hz : 0.0;
    const auto stride = static_cast<std::size_t>(std::max(1.0, std::floor(rig_rate / st.rate_hz)));
    got.clear();
    st.ring_pos[k] = d.read_live(st.rigs[k], st.ring_pos[k], stride, got);
    if (got.empty()) continue;
    // The wire's "cmd", "disp", "force" hold the rig kind's three live values, named in "signals".
    json t, cmd, disp, force;
    for (const auto& s : got) t.push_back(s.t), cmd.push_back(s.v[0]), disp.push_back(s.v[1]), force.push_back(s.v[2]);
    const control::RigInfo info = d.rig_info(st.rigs[k]);
    const auto& names = domain::live_signals(info.kind);
    out += frame("samples", {{"rig", info.name},
                             {"run", got.back().run},
                             {"t", t},
                             {"cmd", cmd},
                             {"disp", disp},
                             {"force", force},
                             {"signals", names},
                             {"status", got.back().status},
                             {"mono_s", got.back().mono_s}});
  }
  return out;
}

bool write(httplib::DataSink& sink, const std::string& s) { return s.empty() || sink.write(s.data(), s.size()); }
}  // namespace

std::string StreamCursor::id() const { return std::to_string(event) + "." + std::to_string(node) + "." + std::to_string(table); }

std::optional<StreamCursor> parse_cursor(const std::string& text) {
  long long e = -1, n = -1, t = -1;
  int used = 0;
  if (text.size() > 60 || std::sscanf(text.c_str(), "%lld.%lld.%lld%n", &e, &n, &t, &used) != 3 || used != static_cast<int>(text.size()) || e < 0 || n < 0 ||
      t < 0 || text.find_first_of("+- ") != std::string::npos)
    return std::nullopt;
  return StreamCursor{e, n, t};
}

void add_stream_route(httplib::Server& s, ApiContext& c) {
  s.Get("/api/stream", guarded([&c](const httplib::Request& req, httplib::Response& res) {
          auto st = std::make_shared<StreamState>();
          st->rate_hz = query_number(req, "rate", 20, 0.1, 1000);
          const std::string last = req.has_header("Last-Event-ID")  ? req.get_header_value("Last-Event-ID")
                                   : req.has_param("last_event_id") ? req.get_param_value("last_event_id")
                                                                    : "";
          if (!last.empty()) {
            const auto cur = parse_cursor(last);
            if (!cur) throw ApiError(400, "invalid parameter", "Last-Event-ID: '" + last + "' is not an id this stream sent (E.N.T)");
            st->cursor = *cur;
          } else {
            st->cursor = newest(reader(c.db_path));
          }
          const std::string rig = req.has_param("rig") ? req.get_param_value("rig") : "";
          for (std::size_t k = 0; k < c.daemon.rig_count(); ++k)
            if (rig.empty() || c.daemon.rig_info(k).name == rig) st->rigs.push_back(k);
          if (st->rigs.empty()) throw ApiError(404, "not found", "rig: no rig named '" + rig + "'");
          for (std::size_t k : st->rigs) st->ring_pos.push_back(c.daemon.live_head(k));
          if (c.stream_clients.fetch_add(1) >= c.config.max_stream_clients) {
            c.stream_clients.fetch_sub(1);
            throw ApiError(503, "too many streams",
                           "at most " + std::to_string(c.config.max_stream_clients) + " event streams at once (http.max_stream_clients)");
          }
          res.set_header("Cache-Control", "no-cache");
          res.set_header("X-Accel-Buffering", "no");
          res.set_chunked_content_provider(
              "text/event-stream",
              [&c, st](std::size_t, httplib::DataSink& sink) {
                if (c.stopping) {
                  sink.done();
                  return true;
                }
                if (!st->hello_sent) {
                  st->hello_sent = true;
                  set_thread_nice(kStreamNice);
                  c.daemon.keep_off_acquisition_cpu(true);
                  return write(sink, "retry: 2000\n\n" + frame("hello", {{"cursor", st->cursor.id()}, {"rate_hz", st->rate_hz}}));
                }
                std::this_thread::sleep_for(kTick);
                std::string out = samples(c.daemon, *st);
                ++st->since_read;
                if (++st->tick % kRecordEvery == 0) {
                  // Read the database only when this process changed a record, or now and then.
                  const std::uint64_t gen = db::record_generation();
                  if (gen != st->seen_generation || st->since_read >= kRecordPollAnyway) {
                    st->seen_generation = gen;  // taken before the read: a change during it is read next time
                    st->since_read = 0;
                    out += records(reader(c.db_path), st->cursor);
                    release_reader();  // a stream holds no connection between its reads
                  }
                }
                if (out.empty() && ++st->quiet >= kKeepAliveEvery) out = ": keep-alive\n\n";
                if (!out.empty()) st->quiet = 0;
                return write(sink, out) && sink.is_writable();
              },
              [&c](bool) {
                release_reader();
                set_thread_nice(kRequestNice);  // a request thread again (stays at 19 without CAP_SYS_NICE)
                c.daemon.keep_off_acquisition_cpu(false);
                c.stream_clients.fetch_sub(1);
              });
        }));
}

}  // namespace hystlab::web
