#pragma once
// The finisher thread: the end of every run (final fits, tables, the campaign's last state) and
// the evaluations during a run (a descent's partial table scored) off the acquisition threads,
// one after another in the order handed over. Stopping finishes what was handed over.
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
  // Other work (an evaluation); an exception it throws is logged, the thread goes on.
  void post(std::function<void()> task);

 private:
  void run();
  void post_task(std::function<void()> task);
  void finish(FinishJob job);
  db::SampleWriter& writer_;
  Work work_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> jobs_;  // the ends of runs and the evaluations, in order
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace hystlab::daemon
