#include "hystlab/daemon/daemon.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <condition_variable>
#include <future>
#include <mutex>

#include "hystlab/daemon/plan.hpp"
#include "hystlab/drivers/rig_factory.hpp"
#include "rig_worker.hpp"

namespace hystlab::daemon {
using nlohmann::json;

struct Daemon::Impl {
  DaemonConfig config;
  db::Store store;  // the main loop's connection
  std::vector<std::unique_ptr<RigWorker>> workers;
  std::unique_ptr<db::SampleWriter> writer;
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
  std::mutex mu;
  std::condition_variable cv;
  std::deque<std::function<void()>> jobs;  // from other threads, run by the main loop
  bool accepting = true;
  const std::atomic<bool>* stop = nullptr;

  explicit Impl(const DaemonConfig& c) : config(c), store(c.db_path) {}

  // Runs f on the main loop with its store and waits for it (at most a few seconds).
  template <class R>
  R on_main(std::function<R()> f) {
    auto task = std::make_shared<std::packaged_task<R()>>(std::move(f));
    auto fut = task->get_future();
    {
      std::lock_guard lk(mu);
      if (!accepting) throw std::runtime_error("the daemon is stopping");
      jobs.emplace_back([task] { (*task)(); });
    }
    cv.notify_one();
    if (fut.wait_for(std::chrono::seconds(10)) != std::future_status::ready)
      throw std::runtime_error("the daemon did not answer within 10 s");
    return fut.get();
  }

  // An operator command, as the CLI's (db) and the API's (queue) both arrive.
  void route(std::int64_t campaign, const std::string& verb) {
    const auto row = store.campaign(campaign);
    if (!row) return;
    for (auto& w : workers)
      if (w->running_campaign == campaign) {
        w->push(verb == "pause" ? Control::pause : verb == "resume" ? Control::resume : verb == "estop" ? Control::estop : Control::abort);
        return;
      }
    if (verb == "resume" && (row->state == "interrupted" || row->state == "paused"))
      store.transition(campaign, "queued", "re-queued to resume: wipe-out preamble, then the rows not yet measured", now_iso());
    else if ((verb == "abort" || verb == "estop") && row->state == "queued")
      store.transition(campaign, "aborted", "aborted by the operator before it started", now_iso());
    else
      store.add_event(campaign, "command", "'" + verb + "' ignored: the campaign is " + row->state, now_iso());
  }

  void store_io_stats() {
    for (auto& w : workers) {
      const auto h = w->rig->health();
      const json stats{{"reads", h.reads}, {"writes", h.writes}, {"errors", h.total_errors()}, {"reconnects", h.reconnects},
                       {"max_transaction_us", h.max_transaction_us}};
      const auto id = w->info.id;
      const std::string now = now_iso();
      writer->post([id, stats, now](db::Store& s) {
        db::Statement st(s.database(), "INSERT INTO io_stats(rig_id, at, stats) VALUES(?,?,?)");
        st.bind(1, id).bind(2, now).bind(3, stats.dump());
        st.step();
      });
    }
  }

  void run_jobs() {
    std::deque<std::function<void()>> todo;
    {
      std::unique_lock lk(mu);
      cv.wait_for(lk, std::chrono::milliseconds(100), [this] { return !jobs.empty(); });
      todo.swap(jobs);
    }
    for (auto& j : todo) j();
  }
};

Daemon::Daemon(const DaemonConfig& config) : impl_(std::make_unique<Impl>(config)) {
  auto& d = *impl_;
  if (const int n = d.store.mark_interrupted(now_iso())) spdlog::warn("{} campaign(s) were left running: now interrupted", n);
  for (const RigEntry& e : config.rigs) {
    auto w = std::make_unique<RigWorker>();
    w->entry = e;
    w->acquisition = config.acquisition;
    // A simulator shares the acquisition's CPU, just below it: its answers are then never queued
    // behind other threads. Not above real time: there its physics catch-up is real work, and at
    // SCHED_FIFO it starved the daemon (a campaign stalled at time scale 100 in an ASan build).
    w->entry.sim.cpu = resolve_cpu(config.acquisition.cpu);
    if (w->entry.sim.realtime_priority < 0)
      w->entry.sim.realtime_priority =
          w->entry.sim.cpu >= 0 && config.acquisition.priority > 1 && e.sim.time_scale <= 1 ? config.acquisition.priority - 1 : 0;
    try {
      w->build_rig(config.base_dir);
    } catch (const drivers::RigConfigError& err) {
      throw ConfigError(std::string("config: ") + err.what());
    }
    w->info.id = d.store.upsert_rig(e.name, e.simulated ? json{{"simulate", {{"time_scale", e.sim.time_scale}, {"rig", e.sim.rig}}}}.dump() : e.driver.dump(), now_iso());
    spdlog::info("rig '{}': {}", e.name, w->info.description);
    d.workers.push_back(std::move(w));
  }
  // The writer's thread starts off the acquisition's CPU and stays there: this kernel does not
  // preempt system calls (PREEMPT_NONE), so its writes and fsyncs on that CPU would hold back the
  // acquisition's wake-ups by milliseconds.
  const bool moved = avoid_cpu(resolve_cpu(config.acquisition.cpu));
  d.writer = std::make_unique<db::SampleWriter>(config.db_path);
  if (moved) (void)avoid_cpu(-1);
}

Daemon::~Daemon() {
  auto& d = *impl_;
  {
    std::lock_guard lk(d.mu);
    d.accepting = false;
  }
  for (auto& w : d.workers)
    if (w->thread.joinable()) w->thread.join();
  d.writer->flush();
  for (auto& w : d.workers)
    if (w->sim) w->sim->stop();
}

void Daemon::run(const std::atomic<bool>& stop) {
  auto& d = *impl_;
  for (auto& w : d.workers)
    w->thread = std::thread(rig_thread, std::ref(*w), d.config.db_path, std::ref(*d.writer), std::cref(stop), d.config.base_dir);
  spdlog::info("hystlabd running: database {}", d.config.db_path);
  auto last_stats = std::chrono::steady_clock::now();
  while (!stop) {
    d.run_jobs();
    for (const auto& c : d.store.take_commands(now_iso())) d.route(c.campaign_id, c.command);
    if (std::chrono::steady_clock::now() - last_stats > std::chrono::seconds(10)) {
      last_stats = std::chrono::steady_clock::now();
      d.store_io_stats();
    }
  }
  spdlog::info("hystlabd stopping: holding rigs, finishing the write batch");
  {
    std::lock_guard lk(d.mu);
    d.accepting = false;
  }
  d.run_jobs();  // what was accepted is carried out (or its caller times out)
  for (auto& w : d.workers) w->thread.join();  // each holds its rig and marks its campaign interrupted
  d.writer->flush();
}

const DaemonConfig& Daemon::config() const noexcept { return impl_->config; }
std::size_t Daemon::rig_count() const noexcept { return impl_->workers.size(); }
const RigInfo& Daemon::rig_info(std::size_t k) const { return impl_->workers.at(k)->info; }
const RigLive& Daemon::rig_live(std::size_t k) const { return impl_->workers.at(k)->live; }
drivers::IoHealthSnapshot Daemon::rig_health(std::size_t k) const { return impl_->workers.at(k)->rig->health(); }
db::WriterStats Daemon::writer_stats() const { return impl_->writer->stats(); }
double Daemon::uptime_s() const noexcept {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - impl_->started).count();
}

std::int64_t Daemon::submit(const std::string& rig_name, const json& plan_json) {
  const Plan plan = parse_plan(plan_json);  // PlanError names the field
  const RigWorker* rig = nullptr;
  if (rig_name.empty()) {
    if (impl_->workers.size() != 1) throw std::invalid_argument("rig: several rigs are configured; name one");
    rig = impl_->workers.front().get();
  } else {
    for (const auto& w : impl_->workers)
      if (w->info.name == rig_name) rig = w.get();
    if (!rig) throw std::invalid_argument("rig: no rig named '" + rig_name + "'");
  }
  const bool shaker_plan = plan.kind == "sine";
  if (shaker_plan != (rig->info.kind == "shaker"))
    throw std::invalid_argument("plan.kind: a " + plan.kind + " plan cannot run on rig '" + rig->info.name + "', a " + rig->info.kind);
  const std::int64_t rig_id = rig->info.id;
  const std::string kind = plan.kind, text = plan_json.dump();
  return impl_->on_main<std::int64_t>([this, rig_id, kind, text] { return impl_->store.create_campaign(rig_id, kind, text, now_iso()); });
}

void Daemon::command(std::int64_t campaign_id, const std::string& verb) {
  if (verb != "pause" && verb != "resume" && verb != "abort" && verb != "estop")
    throw std::invalid_argument("command: '" + verb + "' is not pause, resume, abort or estop");
  impl_->on_main<int>([this, campaign_id, verb] {
    impl_->route(campaign_id, verb);
    return 0;
  });
}

int run_daemon(const DaemonConfig& config, const std::atomic<bool>& stop) {
  Daemon d(config);
  d.run(stop);
  return 0;
}

}  // namespace hystlab::daemon
