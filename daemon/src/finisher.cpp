#include "finisher.hpp"

#include <malloc.h>
#include <spdlog/spdlog.h>

#include "rig_worker.hpp"

namespace hystlab::daemon {

Finisher::Finisher(db::SampleWriter& writer, Work work) : writer_(writer), work_(std::move(work)), thread_([this] { run(); }) {}

Finisher::~Finisher() {
  {
    std::lock_guard lk(mu_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void Finisher::submit(FinishJob job) {
  // A task like the others, in order with them (a descent's evaluation before its campaign's end).
  auto shared = std::make_shared<FinishJob>(std::move(job));
  post_task([this, shared] { finish(std::move(*shared)); });
}

void Finisher::post(std::function<void()> task) {
  post_task([task = std::move(task)] {
    try {
      task();
    } catch (const std::exception& e) {  // an evaluation is extra: the campaign goes on without it
      spdlog::warn("an evaluation failed: {}", e.what());
    }
  });
}

void Finisher::post_task(std::function<void()> task) {
  {
    std::lock_guard lk(mu_);
    jobs_.push_back(std::move(task));
  }
  cv_.notify_all();
}

void Finisher::finish(FinishJob job) {
  const auto id = job.campaign;
  try {
    const RunnerResult r = work_ ? work_(std::move(job)) : finish_campaign(std::move(job), writer_, now_iso);
    spdlog::info("campaign {} finished: {}{}{}", id, to_string(r.end), r.reason.empty() ? "" : ": ", r.reason);
  } catch (const std::exception& e) {  // a fit that throws fails the campaign; the thread goes on
    spdlog::error("campaign {}: finishing failed: {}", id, e.what());
    const std::string now = now_iso(), reason = std::string("finishing failed: ") + e.what();
    writer_.post([id, reason, now](db::Store& s) { s.transition(id, domain::CampaignState::failed, reason, now); });
  }
  // The fits' working memory (the whole record, the solver's matrices) goes back to the system:
  // glibc keeps freed heap of its threads' arenas otherwise, and the daemon's resident size
  // grew with every campaign it finished.
  (void)malloc_trim(0);
}

void Finisher::run() {
  for (;;) {
    std::function<void()> task;
    {
      std::unique_lock lk(mu_);
      cv_.wait(lk, [this] { return stop_ || !jobs_.empty(); });
      if (jobs_.empty()) return;
      task = std::move(jobs_.front());
      jobs_.pop_front();
    }
    task();
  }
}

}  // namespace hystlab::daemon
