#include "hystlab/lab/replication.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>

#include "hystlab/db/replicator.hpp"

namespace hystlab::lab {
namespace {
double mono_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }
}  // namespace

ReplicationThread::ReplicationThread(const control::DaemonInterface& daemon, const LabConfig& config, std::string software)
    : daemon_(daemon), config_(config), software_(std::move(software)) {
  counters_.configured = config_.has_postgres;
}

ReplicationThread::~ReplicationThread() { stop(); }

void ReplicationThread::start() {
  if (!config_.has_postgres || thread_.joinable()) return;
  {
    const std::lock_guard lock(mu_);
    stop_ = false;
  }
  thread_ = std::thread([this] { run(); });
}

void ReplicationThread::stop() noexcept {
  {
    const std::lock_guard lock(mu_);
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

control::ReplicationCounters ReplicationThread::counters() const {
  const std::lock_guard lock(mu_);
  control::ReplicationCounters c = counters_;
  if (thread_.joinable()) c.lag_s = mono_s() - caught_up_at_;  // grows while the thread waits to retry
  return c;
}

bool ReplicationThread::wait_s(double s) {
  std::unique_lock lock(mu_);
  return !cv_.wait_for(lock, std::chrono::duration<double>(s), [this] { return stop_; });
}

void ReplicationThread::failed(const std::string& why) {
  const std::lock_guard lock(mu_);
  if (counters_.error != why) spdlog::warn("lab: replication to PostgreSQL: {} (retrying)", why);
  counters_.error = why;
  counters_.connected = false;
  ++counters_.failures;
}

// Every error is caught here, at the thread's top, and becomes the status's reason: no
// exception from PostgreSQL, SQLite or memory leaves this thread or touches the daemon.
void ReplicationThread::run() noexcept {
  daemon_.keep_off_acquisition_cpu(true);  // low-priority, long-lived work (as the event streams)
  double backoff = 0.5;
  {
    const std::lock_guard lock(mu_);
    caught_up_at_ = mono_s();
  }
  std::unique_ptr<db::Replicator> rep;
  for (;;) {
    bool again = false;
    try {
      if (!rep)
        rep = std::make_unique<db::Replicator>(daemon_.db_path(), db::ReplicaIdentity{config_.name, config_.daemon, software_, config_.url},
                                               config_.postgres.conninfo, config_.postgres.password, config_.postgres.batch_rows);
      const double began = mono_s();
      const db::PassResult r = rep->pass(10);
      again = !r.caught_up;
      backoff = 0.5;
      const std::lock_guard lock(mu_);
      if (r.caught_up) caught_up_at_ = began;
      if (!counters_.connected) spdlog::info("lab: replicating to PostgreSQL as daemon {} of lab {}", config_.daemon, config_.name);
      counters_.connected = true;
      counters_.error.clear();
      counters_.samples += r.samples;
      counters_.rows += r.rows;
      counters_.backlog_samples = rep->backlog_samples();
      ++counters_.passes;
    } catch (const db::PgError& e) {
      failed(e.what());
      if (rep) rep->disconnect();  // a new session next time: the marks are read back from PostgreSQL
    } catch (const std::exception& e) {
      failed(std::string("replication failed: ") + e.what());
      rep.reset();  // the SQLite connection too
    } catch (...) {
      failed("replication failed: unknown error");
      rep.reset();
    }
    const bool ok = counters().connected;
    if (!wait_s(again ? 0.0 : ok ? config_.postgres.period_s : backoff)) return;
    if (!ok) backoff = std::min(backoff * 2, 30.0);
  }
}

}  // namespace hystlab::lab
