// The daemon's life: start-up (left-overs cleared, the rigs built, the writer, finisher and loader
// started), the main loop, and the stop. Its state: daemon_impl.hpp; its requests: daemon_requests.cpp.
#include "hystlab/daemon/daemon.hpp"

#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <system_error>
#include <thread>
#include <utility>

#include "daemon_impl.hpp"
#include "hystlab/drivers/rig_factory.hpp"

namespace hystlab::daemon {

namespace {
// An HTTP HDF5 export's temporary file (web/src/routes_h5.cpp) is unlinked once open; a kill in
// between left it beside the database for good. Any left from an earlier run go at start-up.
void remove_leftover_exports(const std::string& db_path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path dir = fs::absolute(db_path, ec).parent_path();
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind("hystlab-export-", 0) != 0 || it->path().extension() != ".h5") continue;
    std::error_code rm;
    if (fs::remove(it->path(), rm)) spdlog::warn("removed a left-over export file: {}", it->path().string());
  }
}
}  // namespace

Daemon::Daemon(const DaemonConfig& config) : impl_(std::make_unique<Impl>(config)) {
  auto& d = *impl_;
  remove_leftover_exports(config.db_path);
  if (const int n = d.store.mark_interrupted(now_iso())) spdlog::warn("{} campaign(s) were left running: now interrupted", n);
  if (const int n = d.store.hold_queued(now_iso()))
    spdlog::warn("{} queued campaign(s) held after the restart: nothing moves until an operator releases them (resume)", n);
  for (const RigEntry& e : config.rigs) {
    auto w = std::make_unique<RigWorker>();
    w->entry = e;
    w->acquisition = config.acquisition;
    // A simulator shares the acquisition's CPU, just below it: its answers are then never queued
    // behind other threads. Not above real time: there its physics catch-up is real work, and at
    // SCHED_FIFO it starved the daemon (a campaign stalled at time scale 100 in an ASan build).
    w->entry.sim.cpu = resolve_cpu(config.acquisition.cpu);
    if (w->entry.sim.realtime_priority < 0)
      w->entry.sim.realtime_priority = w->entry.sim.cpu >= 0 && config.acquisition.priority > 1 && e.sim.time_scale <= 1 ? config.acquisition.priority - 1 : 0;
    try {
      w->build_rig(config.base_dir);
    } catch (const drivers::RigConfigError& err) {
      throw ConfigError(std::string("config: ") + err.what());
    }
    w->info.id = d.store.upsert_rig(e.name, e.simulated ? json{{"simulate", {{"time_scale", e.sim.time_scale}, {"rig", e.sim.rig}}}}.dump() : e.driver.dump(),
                                    now_iso());
    spdlog::info("rig '{}': {}", e.name, w->info.description);
    d.workers.push_back(std::move(w));
  }
  // The writer's thread starts off the acquisition's CPU and stays there: this kernel does not
  // preempt system calls (PREEMPT_NONE), so its writes and fsyncs on that CPU would hold back the
  // acquisition's wake-ups by milliseconds.
  const bool moved = avoid_cpu(resolve_cpu(config.acquisition.cpu));
  d.writer = std::make_unique<db::SampleWriter>(config.db_path);
  d.finisher = std::make_unique<Finisher>(*d.writer, [&d](FinishJob j) {
    struct Done {
      Impl& d;
      std::int64_t id;
      ~Done() {
        std::lock_guard lk(d.finishing_mu);
        d.finishing.erase(id);
      }
    } const done{d, j.campaign};
    return finish_campaign(std::move(j), *d.writer, now_iso);
  });
  d.loader = std::make_unique<ResumeLoader>(config.db_path);
  if (moved) (void)avoid_cpu(-1);
}

Daemon::~Daemon() {
  auto& d = *impl_;
  {
    std::lock_guard lk(d.mu);
    d.accepting = false;
  }
  d.loader.reset();
  for (auto& w : d.workers)
    if (w->thread.joinable()) w->thread.join();
  d.finisher.reset();  // what was handed over is finished
  d.writer->flush();
  for (auto& w : d.workers)
    if (w->sim) w->sim->stop();
}

void Daemon::run(const std::atomic<bool>& stop) {
  auto& d = *impl_;
  Offload offload;
  offload.finish = [&d](FinishJob j) {
    {
      std::lock_guard lk(d.finishing_mu);
      d.finishing.insert(j.campaign);
    }
    d.finisher->submit(std::move(j));
  };
  offload.background = [&d](std::function<void()> task) { d.finisher->post(std::move(task)); };
  for (auto& w : d.workers) w->thread = std::thread(rig_thread, std::ref(*w), std::ref(*d.writer), offload, std::cref(stop), d.config.base_dir);
  spdlog::info("hystlabd running: database {}", d.config.db_path);
  auto last_stats = std::chrono::steady_clock::now();
  while (!stop) {
    try {
      d.run_jobs(d.db_backoff_s > 0 ? d.db_backoff_s : 0.1);
      d.poll_database();
      if (std::chrono::steady_clock::now() - last_stats > std::chrono::seconds(10)) {
        last_stats = std::chrono::steady_clock::now();
        d.store_io_stats();
      }
    } catch (const std::exception& e) {  // never out of run(): the HTTP server and the rigs depend on it
      spdlog::error("main loop: {}", e.what());
    }
  }
  spdlog::info("hystlabd stopping: holding rigs, finishing the write batch");
  {
    std::lock_guard lk(d.mu);
    d.accepting = false;
  }
  try {
    d.run_jobs(0);  // what was accepted is carried out (or its caller times out)
  } catch (const std::exception& e) {
    spdlog::error("main loop: {}", e.what());
  }
  d.loader.reset();  // a load under way finishes; its job is dropped (no longer accepted): the campaign stays queued, held at the next start
  for (auto& w : d.workers) w->thread.join();  // each holds its rig and marks its campaign interrupted
  d.finisher.reset();
  d.writer->flush();
}

int run_daemon(const DaemonConfig& config, const std::atomic<bool>& stop) {
  Daemon d(config);
  d.run(stop);
  return 0;
}

}  // namespace hystlab::daemon
