#pragma once
// The finisher thread: the end of every run (final fits, tables, the campaign's last state) off
// the acquisition threads, one job after another. Stopping finishes what was handed over.
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>

#include "hystlab/daemon/campaign_runner.hpp"

namespace hystlab::daemon {

class Finisher {
 public:
  using Work = std::function<RunnerResult(FinishJob)>;
  // work: what finishing a job is (finish_campaign by default; the safety matrix injects a failure).
  explicit Finisher(db::SampleWriter& writer, Work work = {});
  ~Finisher();  // finishes every job handed over, then stops
  Finisher(const Finisher&) = delete;
  Finisher& operator=(const Finisher&) = delete;
  void submit(FinishJob job);

 private:
  void run();
  db::SampleWriter& writer_;
  Work work_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<FinishJob> jobs_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace hystlab::daemon
