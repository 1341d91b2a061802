#pragma once
// One rig inside the daemon: its driver (and supervised simulator), its acquisition thread that
// runs the rig's queued campaigns one after another, and the controls queued for the campaign.
#include <atomic>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/daemon/daemon.hpp"
#include "hystlab/daemon/live_feed.hpp"
#include "hystlab/db/sample_writer.hpp"
#include "hystlab/drivers/rig.hpp"
#include "sim_child.hpp"

namespace hystlab::daemon {

[[nodiscard]] std::string now_iso();

struct RigWorker {
  RigEntry entry;
  AcquisitionSettings acquisition;
  RigInfo info;
  std::unique_ptr<SimChild> sim;
  std::unique_ptr<drivers::Rig> rig;
  RigLive live;
  std::mutex mu;
  std::deque<Control> controls;
  std::atomic<std::int64_t> running_campaign{0};
  std::thread thread;

  void build_rig(const std::string& base);  // throws drivers::RigConfigError
  void push(Control c);
  std::optional<Control> pop();
};

// The rig's acquisition thread: queued campaigns in order; between them, a sample now and then
// so the rig's live view stays fresh.
void rig_thread(RigWorker& w, const std::string& db_path, db::SampleWriter& writer, const std::atomic<bool>& stop,
                const std::string& base);

}  // namespace hystlab::daemon
