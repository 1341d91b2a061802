#pragma once
// A resumed campaign's earlier record: its runs' samples, for the fits that use every run. A long
// campaign holds 10^7 rows, seconds to read; they are read here, on a thread of its own with its
// own connection, never on the main loop, which carries the operators' commands and the other
// rigs' submissions. The job reaches its rig's queue once its record is in.
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/db/store.hpp"

namespace hystlab::daemon {

// The earlier runs' samples into job.prior_series (every campaign run, in order) and the last
// validation run that holds samples into job.prior_validation.
void read_prior_record(db::Store& store, CampaignJob& job);

class ResumeLoader {
 public:
  explicit ResumeLoader(std::string db_path);
  ~ResumeLoader();  // the load under way is finished; those not begun are dropped (their campaigns stay queued)
  ResumeLoader(const ResumeLoader&) = delete;
  ResumeLoader& operator=(const ResumeLoader&) = delete;
  // On the loader's thread: the record read into the job, then done(job); or failed(why) when
  // the database refused (the caller hands the campaign over again later).
  void load(CampaignJob job, std::function<void(CampaignJob)> done, std::function<void(const std::string&)> failed);

 private:
  struct Load {
    CampaignJob job;
    std::function<void(CampaignJob)> done;
    std::function<void(const std::string&)> failed;
  };
  void run();
  std::string path_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<Load> loads_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace hystlab::daemon
