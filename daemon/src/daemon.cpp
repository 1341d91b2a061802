#include "hystlab/daemon/daemon.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <ctime>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <thread>

#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/db/sample_writer.hpp"
#include "hystlab/drivers/rig_factory.hpp"
#include "sim_child.hpp"

namespace hystlab::daemon {
namespace {
using nlohmann::json;

std::string now_iso() {
  const auto t = std::chrono::system_clock::now();
  const std::time_t s = std::chrono::system_clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&s, &tm);
  char buf[96];
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(t.time_since_epoch()).count() % 1000;
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday,
                tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<int>(ms));
  return buf;
}

// One rig: its driver, its acquisition thread, and the commands queued for its campaign.
struct RigWorker {
  RigEntry entry;
  std::int64_t rig_id = 0;
  std::unique_ptr<SimChild> sim;
  std::unique_ptr<drivers::Rig> rig;
  std::mutex mu;
  std::deque<Control> controls;
  std::atomic<std::int64_t> running_campaign{0};
  std::thread thread;

  void build_rig(const std::string& base) {
    json cfg = entry.driver;
    if (entry.simulated) {
      if (!sim) sim = std::make_unique<SimChild>(entry.sim);
      cfg = json{{"name", entry.name}, {"transport", "modbus-tcp"}, {"host", "127.0.0.1"}, {"port", sim->ensure_running()},
                 {"rig", entry.sim.rig}};
      entry.time_scale = entry.sim.time_scale;
    }
    cfg["name"] = entry.name;
    rig = drivers::make_rig(cfg, "rig '" + entry.name + "'", base);
  }
  std::optional<Control> pop() {
    std::lock_guard lk(mu);
    if (controls.empty()) return std::nullopt;
    const Control c = controls.front();
    controls.pop_front();
    return c;
  }
};

void run_one(RigWorker& w, std::int64_t id, db::Store& store, db::SampleWriter& writer, const std::atomic<bool>& stop,
             const std::string& base) {
  const auto row = store.campaign(id);
  if (!row) return;
  Plan plan;
  try {
    plan = parse_plan(json::parse(row->plan));
  } catch (const std::exception& e) {  // a plan stored by an older or foreign tool: fail it, say why
    store.transition(id, "failed", e.what(), now_iso());
    return;
  }
  if (w.entry.simulated && w.sim && w.sim->ensure_running() != w.sim->port()) w.build_rig(base);
  RunnerContext ctx(*w.rig, writer, store);
  ctx.time_scale = w.entry.time_scale;
  ctx.stop = &stop;
  ctx.now_iso = now_iso;
  ctx.next_control = [&w] { return w.pop(); };
  for (const auto& [a, b, fa, fab] : store.fot_nodes_of_campaign(id)) ctx.prior_nodes.push_back({a, b, fa, fab});
  ctx.on_state = [&w, id](const std::string& s) { spdlog::info("rig '{}': campaign {} {}", w.entry.name, id, s); };
  w.running_campaign = id;
  const RunnerResult r = run_campaign(id, plan, ctx);
  w.running_campaign = 0;
  spdlog::info("rig '{}': campaign {} ended {} ({} samples, {} missed deadlines, {} dropped){}{}", w.entry.name, id, r.state,
               r.samples, r.missed_deadlines, r.dropped, r.reason.empty() ? "" : ": ", r.reason);
}

void rig_thread(RigWorker& w, const std::string& db_path, db::SampleWriter& writer, const std::atomic<bool>& stop,
                const std::string& base) {
  db::Store store(db_path);
  while (!stop) {
    const auto queued = store.queued_campaigns(w.rig_id);
    if (!queued.empty()) {
      run_one(w, queued.front(), store, writer, stop, base);
      continue;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

// Main thread: operator commands from the store to the right rig, and I/O statistics.
void route_commands(db::Store& store, std::vector<std::unique_ptr<RigWorker>>& workers) {
  for (const auto& c : store.take_commands(now_iso())) {
    const auto row = store.campaign(c.campaign_id);
    if (!row) continue;
    bool routed = false;
    for (auto& w : workers)
      if (w->running_campaign == c.campaign_id) {
        const Control k = c.command == "pause"    ? Control::pause
                          : c.command == "resume" ? Control::resume
                          : c.command == "estop"  ? Control::estop
                                                  : Control::abort;
        std::lock_guard lk(w->mu);
        w->controls.push_back(k);
        routed = true;
      }
    if (routed) continue;
    if (c.command == "resume" && (row->state == "interrupted" || row->state == "paused"))
      store.transition(c.campaign_id, "queued", "re-queued to resume: wipe-out preamble, then the rows not yet measured", now_iso());
    else if (c.command == "abort" && row->state == "queued")
      store.transition(c.campaign_id, "aborted", "aborted by the operator before it started", now_iso());
    else
      store.add_event(c.campaign_id, "command", "'" + c.command + "' ignored: the campaign is " + row->state, now_iso());
  }
}
}  // namespace

int run_daemon(const DaemonConfig& config, const std::atomic<bool>& stop) {
  db::Store store(config.db_path);
  if (const int n = store.mark_interrupted(now_iso())) spdlog::warn("{} campaign(s) were left running: now interrupted", n);
  std::vector<std::unique_ptr<RigWorker>> workers;
  for (const RigEntry& e : config.rigs) {
    auto w = std::make_unique<RigWorker>();
    w->entry = e;
    try {
      w->build_rig(config.base_dir);
    } catch (const drivers::RigConfigError& err) {
      throw ConfigError(std::string("config: ") + err.what());
    }
    w->rig_id = store.upsert_rig(e.name, e.simulated ? json{{"simulate", {{"time_scale", e.sim.time_scale}}}}.dump() : e.driver.dump(), now_iso());
    spdlog::info("rig '{}': {}", e.name, w->rig->describe());
    workers.push_back(std::move(w));
  }
  db::SampleWriter writer(config.db_path);
  for (auto& w : workers) w->thread = std::thread(rig_thread, std::ref(*w), config.db_path, std::ref(writer), std::cref(stop), config.base_dir);
  spdlog::info("hystlabd running: database {}", config.db_path);
  auto last_stats = std::chrono::steady_clock::now();
  while (!stop) {
    route_commands(store, workers);
    if (std::chrono::steady_clock::now() - last_stats > std::chrono::seconds(10)) {
      last_stats = std::chrono::steady_clock::now();
      for (auto& w : workers) {
        const auto h = w->rig->health();
        const json stats{{"reads", h.reads}, {"writes", h.writes}, {"errors", h.total_errors()}, {"reconnects", h.reconnects},
                         {"max_transaction_us", h.max_transaction_us}};
        const auto id = w->rig_id;
        const std::string now = now_iso();
        writer.post([id, stats, now](db::Store& s) {
          db::Statement st(s.database(), "INSERT INTO io_stats(rig_id, at, stats) VALUES(?,?,?)");
          st.bind(1, id).bind(2, now).bind(3, stats.dump());
          st.step();
        });
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  spdlog::info("hystlabd stopping: holding rigs, finishing the write batch");
  for (auto& w : workers) w->thread.join();  // each holds its rig and marks its campaign interrupted
  writer.flush();
  for (auto& w : workers)
    if (w->sim) w->sim->stop();
  return 0;
}

}  // namespace hystlab::daemon
