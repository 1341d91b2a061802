#pragma once
// The db writer thread: samples arrive through a bounded SPSC ring (the acquisition thread never
// waits on the disk), and are committed in batches at most batch_window_s apart (synchronous=FULL
// by default, so an acknowledged batch survives a power cut). A full ring is counted, not hidden.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "hystlab/db/spsc_ring.hpp"
#include "hystlab/db/store.hpp"

namespace hystlab::db {

struct WriterOptions {
  std::size_t capacity = 1U << 17;  // ring slots (power of two): about 2 minutes at 1 kHz
  double batch_window_s = 0.1;      // a kill -9 loses at most this much (and what is in flight)
  std::size_t max_batch = 50'000;
  bool synchronous_full = true;
};

struct WriterStats {
  std::uint64_t pushed = 0, dropped_full = 0, written = 0, commits = 0, errors = 0;
  std::size_t depth = 0;
  double max_commit_ms = 0;
  std::int64_t acknowledged_run = 0, acknowledged_seq = -1;  // the last row known to be on disk
  std::string last_error;
};

class SampleWriter {
 public:
  SampleWriter(const std::string& path, WriterOptions options = {});
  ~SampleWriter();  // commits what is queued, then stops
  SampleWriter(const SampleWriter&) = delete;
  SampleWriter& operator=(const SampleWriter&) = delete;

  // Acquisition thread only (single producer). Never blocks; false when the ring is full.
  bool try_push(const SampleRow& row) noexcept { return try_push(AnyRow(row)); }
  bool try_push(const ShakerRow& row) noexcept { return try_push(AnyRow(row)); }
  bool try_push(const AnyRow& row) noexcept {
    if (ring_.try_push(row)) {
      pushed_.fetch_add(1, std::memory_order_relaxed);
      return true;
    }
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  // Other writes (events, FOT nodes, evaluations) run on the writer thread after the samples
  // queued before them, so the caller never waits on the disk. Brief lock, no I/O.
  void post(std::function<void(Store&)> job);
  // Runs f on the writer thread and waits at most timeout_s for its result: nothing when it did
  // not come in time or threw (a busy or failing database). For the few answers the acquisition
  // thread needs before it arms a rig (a new run's id); never inside the loop.
  template <class R>
  std::optional<R> call(std::function<R(Store&)> f, double timeout_s) {
    auto p = std::make_shared<std::promise<R>>();
    auto fut = p->get_future();
    post([p, f = std::move(f)](Store& s) {
      try {
        p->set_value(f(s));
      } catch (...) {
        p->set_exception(std::current_exception());
      }
    });
    {
      std::lock_guard lk(mu_);
      urgent_ = true;  // the writer wakes now, not at the end of its batch window
    }
    cv_.notify_all();
    if (fut.wait_for(std::chrono::duration<double>(timeout_s)) != std::future_status::ready) return std::nullopt;
    try {
      return fut.get();
    } catch (const std::exception&) {
      return std::nullopt;
    }
  }
  // Blocks until every row pushed (and job posted) before the call is done (not for the acquisition thread).
  void flush();
  [[nodiscard]] WriterStats stats() const;

 private:
  void run();
  bool write_batch(std::vector<AnyRow>& batch, Store& store);

  WriterOptions opt_;
  std::string path_;
  SpscRing<AnyRow> ring_;
  std::atomic<std::uint64_t> pushed_{0}, dropped_{0}, written_{0}, commits_{0}, errors_{0};
  std::atomic<std::int64_t> ack_run_{0}, ack_seq_{-1};
  std::atomic<double> max_commit_ms_{0};
  mutable std::mutex mu_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::uint64_t flush_requested_ = 0, flush_done_ = 0;
  bool urgent_ = false;
  std::string last_error_;
  std::deque<std::function<void(Store&)>> jobs_;
  std::thread thread_;
};

}  // namespace hystlab::db
