#include "hystlab/db/sample_writer.hpp"

#include <chrono>

namespace hystlab::db {

SampleWriter::SampleWriter(const std::string& path, WriterOptions options) : opt_(options), path_(path), ring_(options.capacity) {
  // Open (and migrate) here, so a bad path fails at start-up in the caller, not in the thread.
  { Store probe(path_, opt_.synchronous_full); }
  thread_ = std::thread([this] { run(); });
}

SampleWriter::~SampleWriter() {
  {
    std::lock_guard lk(mu_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void SampleWriter::post(std::function<void(Store&)> job) {
  std::lock_guard lk(mu_);
  jobs_.push_back(std::move(job));
}

void SampleWriter::flush() {
  std::unique_lock lk(mu_);
  const std::uint64_t ticket = ++flush_requested_;
  cv_.notify_all();
  cv_.wait(lk, [&] { return flush_done_ >= ticket || stop_; });
}

WriterStats SampleWriter::stats() const {
  WriterStats s;
  s.pushed = pushed_.load();
  s.dropped_full = dropped_.load();
  s.written = written_.load();
  s.commits = commits_.load();
  s.errors = errors_.load();
  s.depth = ring_.size();
  s.max_commit_ms = max_commit_ms_.load();
  s.acknowledged_run = ack_run_.load();
  s.acknowledged_seq = ack_seq_.load();
  std::lock_guard lk(mu_);
  s.last_error = last_error_;
  return s;
}

bool SampleWriter::write_batch(std::vector<AnyRow>& batch, Store& store) {
  if (batch.empty()) return true;
  const auto t0 = std::chrono::steady_clock::now();
  try {
    Transaction tx(store.database());
    store.insert_rows(batch);
    tx.commit();
  } catch (const DbError& e) {  // kept for the next attempt; counted and reported, never silent
    errors_.fetch_add(1);
    std::lock_guard lk(mu_);
    last_error_ = e.what();
    return false;
  }
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (ms > max_commit_ms_.load()) max_commit_ms_.store(ms);
  written_.fetch_add(batch.size());
  commits_.fetch_add(1);
  std::visit([this](const auto& r) { ack_run_.store(r.run_id), ack_seq_.store(r.seq); }, batch.back());
  batch.clear();
  return true;
}

void SampleWriter::run() {
  Store store(path_, opt_.synchronous_full);
  std::vector<AnyRow> batch;
  batch.reserve(opt_.max_batch);
  const auto window = std::chrono::duration<double>(opt_.batch_window_s);
  for (;;) {
    bool stopping = false;
    std::uint64_t flush_ticket = 0;
    {
      std::unique_lock lk(mu_);
      cv_.wait_for(lk, window, [&] { return stop_ || urgent_ || flush_requested_ > flush_done_; });
      urgent_ = false;
      stopping = stop_;
      flush_ticket = flush_requested_;
    }
    // Everything queued now goes out, in transactions of at most max_batch rows.
    bool ok = true;
    while (ok) {
      if (batch.size() < opt_.max_batch) ring_.drain(batch, opt_.max_batch - batch.size());
      if (batch.empty()) break;
      ok = write_batch(batch, store);
    }
    std::deque<std::function<void(Store&)>> jobs;
    {
      std::lock_guard lk(mu_);
      jobs.swap(jobs_);
    }
    for (auto& job : jobs) {
      try {
        job(store);
      } catch (const std::exception& e) {
        errors_.fetch_add(1);
        std::lock_guard lk(mu_);
        last_error_ = e.what();
      }
    }
    {
      std::lock_guard lk(mu_);
      if (ok) flush_done_ = flush_ticket;
    }
    cv_.notify_all();
    if (stopping && (ok || errors_.load() > 100)) return;
  }
}

}  // namespace hystlab::db
