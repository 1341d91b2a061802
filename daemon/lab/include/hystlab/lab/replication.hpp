#pragma once
// The replication thread (docs/LAB.md): one thread of its own, with its own read connection to
// the daemon's SQLite file, that copies every run to the lab's PostgreSQL (db::Replicator) a pass
// at a time, at most every period_s while there is nothing to copy and back to back while there
// is a backlog. A lost server, a wrong password or a newer schema is a status with its reason and
// a retry with back-off (0.5 s doubling to 30 s), never an exception out of the thread: the daemon
// goes on acquiring whatever the lab database does.
//
// Thread rule: start/stop from the owner's thread; counters() from any thread.
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "hystlab/control/daemon_interface.hpp"
#include "hystlab/control/values.hpp"
#include "hystlab/lab/lab_config.hpp"

namespace hystlab::lab {

class ReplicationThread {
 public:
  ReplicationThread(const control::DaemonInterface& daemon, const LabConfig& config, std::string software);
  ~ReplicationThread();  // stop()
  ReplicationThread(const ReplicationThread&) = delete;
  ReplicationThread& operator=(const ReplicationThread&) = delete;

  void start();
  void stop() noexcept;  // waits for the pass in progress (at most 10 batches); idempotent
  [[nodiscard]] control::ReplicationCounters counters() const;

 private:
  void run() noexcept;
  bool wait_s(double s);  // false when stopping
  void failed(const std::string& why);

  const control::DaemonInterface& daemon_;
  LabConfig config_;
  std::string software_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  bool stop_ = false;
  control::ReplicationCounters counters_;
  double caught_up_at_ = 0;  // steady seconds: when the last pass that left nothing behind began
  std::thread thread_;
};

}  // namespace hystlab::lab
