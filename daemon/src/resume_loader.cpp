#include "resume_loader.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <limits>
#include <memory>

namespace hystlab::daemon {

void read_prior_record(db::Store& store, CampaignJob& job) {
  constexpr auto kAll = std::numeric_limits<std::int64_t>::max();
  for (const std::int64_t run : store.runs_of_campaign(job.id, domain::RunRole::campaign)) {  // never the validation runs
    store.for_each_sample(run, 0, kAll, [&job](const db::SampleRow& r) { job.prior_series.add(r.disp, r.force); });
    job.prior_run = run;
  }
  // The last validation run that holds samples: a resume with every node measured scores its
  // tables on it (an interruption during the validation run or the finishing left it there).
  const std::vector<std::int64_t> vruns = store.runs_of_campaign(job.id, domain::RunRole::validation);
  const auto last = std::find_if(vruns.rbegin(), vruns.rend(), [&store](std::int64_t run) { return store.sample_count(run) > 0; });
  if (last != vruns.rend()) {
    store.for_each_sample(*last, 0, kAll, [&job](const db::SampleRow& r) { job.prior_validation.add(r.disp, r.force); });
    job.prior_validation_run = *last;
  }
}

ResumeLoader::ResumeLoader(std::string db_path) : path_(std::move(db_path)), thread_([this] { run(); }) {}

ResumeLoader::~ResumeLoader() {
  {
    std::lock_guard lk(mu_);
    stop_ = true;
    loads_.clear();
  }
  cv_.notify_all();
  thread_.join();
}

void ResumeLoader::load(CampaignJob job, std::function<void(CampaignJob)> done, std::function<void(const std::string&)> failed) {
  {
    std::lock_guard lk(mu_);
    loads_.push_back({std::move(job), std::move(done), std::move(failed)});
  }
  cv_.notify_all();
}

void ResumeLoader::run() {
  std::unique_ptr<db::Store> store;  // opened at the first load: most daemons never resume
  for (;;) {
    Load l;
    {
      std::unique_lock lk(mu_);
      cv_.wait(lk, [this] { return stop_ || !loads_.empty(); });
      if (stop_) return;
      l = std::move(loads_.front());
      loads_.pop_front();
    }
    try {
      if (!store) store = std::make_unique<db::Store>(path_);
      read_prior_record(*store, l.job);
    } catch (const std::exception& e) {  // a busy or failing database: said, and the campaign handed over again later
      spdlog::warn("campaign {}: its earlier samples were not read ({}); tried again", l.job.id, e.what());
      store.reset();
      l.failed(e.what());
      continue;
    }
    l.done(std::move(l.job));
  }
}

}  // namespace hystlab::daemon
