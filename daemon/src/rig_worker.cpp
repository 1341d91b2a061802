#include "rig_worker.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstring>
#include <ctime>

#include "hystlab/drivers/rig_factory.hpp"
#include "monotonic_clock.hpp"

namespace hystlab::daemon {
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

void RigWorker::build_rig(const std::string& base) {
  json cfg = entry.driver;
  if (entry.simulated) {
    if (!sim) sim = std::make_unique<SimChild>(entry.sim);
    // In real time the simulated controller is read as a real one is best read: in blocks from its
    // own sample buffer. Faster than real time its clock outruns any reader; the latest value then.
    cfg = json{{"name", entry.name}, {"transport", "modbus-tcp"}, {"host", "127.0.0.1"}, {"port", sim->ensure_running()},
               {"rig", entry.sim.rig}, {"block_reads", entry.sim.rig == "load_frame" && entry.sim.time_scale <= 1}};
    entry.time_scale = entry.sim.time_scale;
  }
  cfg["name"] = entry.name;
  rig = drivers::make_rig(cfg, "rig '" + entry.name + "'", base);
  info.name = entry.name;
  info.simulated = entry.simulated;
  info.kind = cfg.value("rig", std::string("load_frame"));
  info.description = rig->describe();
}

void RigWorker::push(Control c) {
  std::lock_guard lk(mu);
  controls.push_back(c);
}

std::optional<Control> RigWorker::pop() {
  std::lock_guard lk(mu);
  if (controls.empty()) return std::nullopt;
  const Control c = controls.front();
  controls.pop_front();
  return c;
}

namespace {
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
  {
    std::lock_guard lk(w.mu);
    w.controls.clear();  // commands meant for an earlier campaign
  }
  RunnerContext ctx(*w.rig, writer, store);
  ctx.time_scale = w.entry.time_scale;
  ctx.stop = &stop;
  ctx.now_iso = now_iso;
  ctx.next_control = [&w] { return w.pop(); };
  ctx.live = &w.live;
  for (const auto& [a, b, fa, fab] : store.fot_nodes_of_campaign(id)) ctx.prior_nodes.push_back({a, b, fa, fab});
  ctx.on_state = [&w, id](const std::string& s) { spdlog::info("rig '{}': campaign {} {}", w.entry.name, id, s); };
  w.live.sample_rate_hz = plan.sample_rate_hz;
  w.live.campaign = id;
  w.running_campaign = id;
  const RunnerResult r = run_campaign(id, plan, ctx);
  w.running_campaign = 0;
  w.live.campaign = 0;
  spdlog::info("rig '{}': campaign {} ended {} ({} samples, {} missed deadlines, {} late wake-ups, {} dropped){}{}", w.entry.name, id,
               r.state, r.samples, r.missed_deadlines, r.late_wakeups, r.dropped, r.reason.empty() ? "" : ": ", r.reason);
}

// Between campaigns: one read, shown live (run 0). Errors are the driver's to count and log.
void idle_sample(RigWorker& w, double t) {
  if (w.info.kind == "shaker") {
    drivers::ShakerSample s;
    if (!w.rig->read_shaker(t, s))
      w.live.ring.push({mono_now(), t, s.base_displacement_mm, s.mass_displacement_mm, s.mass_accel_m_s2, 0, s.status_word});
    return;
  }
  drivers::RigSample s;
  if (!w.rig->read_sample(t, s)) w.live.ring.push({mono_now(), t, s.command_mm, s.displacement_mm, s.force_N, 0, s.status_word});
}

}  // namespace

void rig_thread(RigWorker& w, const std::string& db_path, db::SampleWriter& writer, const std::atomic<bool>& stop,
                const std::string& base) {
  // Ahead of everything else in the process when the system allows it; otherwise it says so once.
  spdlog::info("rig '{}': acquisition thread at {}", w.entry.name, enter_acquisition_thread(w.acquisition));
  db::Store store(db_path);
  const double t0 = mono_now();
  (void)w.rig->connect(0.0);
  while (!stop) {
    const auto queued = store.queued_campaigns(w.info.id);
    if (!queued.empty()) {
      run_one(w, queued.front(), store, writer, stop, base);
      continue;
    }
    idle_sample(w, (mono_now() - t0) * w.entry.time_scale);
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

}  // namespace hystlab::daemon
