#pragma once
// One rig inside the daemon: its driver (and supervised simulator), its supervisor, and its
// acquisition thread, which takes campaigns and operator commands from in-process queues (never
// from the database) and runs them one after another. Everything it stores goes through the
// writer thread; the final fits through the finisher.
#include <atomic>
#include <condition_variable>
#include <deque>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "hystlab/control/values.hpp"
#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/daemon/config.hpp"
#include "hystlab/daemon/live_feed.hpp"
#include "hystlab/daemon/supervisor.hpp"
#include "hystlab/db/sample_writer.hpp"
#include "hystlab/domain/envelope.hpp"
#include "hystlab/drivers/rig.hpp"
#include "sim_child.hpp"

namespace hystlab::daemon {

using control::CommandOutcome;
using control::RigCommand;
using control::RigInfo;
using control::RigSupervision;

struct RigWorker {
  RigEntry entry;
  AcquisitionSettings acquisition;
  RigInfo info;
  std::unique_ptr<SimChild> sim;
  std::unique_ptr<drivers::Rig> rig;
  std::unique_ptr<Supervisor> supervisor;
  RigLive live;
  std::thread thread;
  std::atomic<std::int64_t> running_campaign{0};
  int idle_misses = 0;  // failed idle reads in a row (the acquisition thread's)

  void build_rig(const std::string& base);  // throws drivers::RigConfigError
  // From other threads: a campaign, a campaign control, a rig command. Never blocks on I/O. A rig
  // command's future is set by the acquisition thread once it is carried out, confirmed by the
  // rig, refused, or found not to apply.
  void push_job(CampaignJob job);
  void push_control(Control c);
  std::future<CommandOutcome> push_rig_command(RigCommand c);
  // Takes a queued (not yet started) campaign out of the queue; false when it is not there.
  bool cancel_queued(std::int64_t campaign);
  [[nodiscard]] bool has_queued(std::int64_t campaign);
  [[nodiscard]] RigSupervision snapshot() const;

  // The acquisition thread's side.
  std::optional<CampaignJob> pop_job();
  std::optional<Control> pop_control();
  // The stop channel: the rig's commands taken and carried out, and those taken earlier settled
  // against what the rig now reports. Called on every period in every phase (idle, arming, every
  // tick of a campaign whatever it is doing), so that nothing waits behind a campaign.
  void service(double t);
  void wait(double seconds);
  void record(const RigTransition& t);  // the supervisor's transitions, for the API and the log
  void update_snapshot(const StatusView& v, double x, double f, bool have_sample);

 private:
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::deque<CampaignJob> jobs_;
  std::deque<Control> controls_;
  struct PendingCommand {
    RigCommand command{};
    std::shared_ptr<std::promise<CommandOutcome>> answer;
    double asked_mono = 0;  // host seconds when it was asked
  };
  std::deque<PendingCommand> rig_commands_;
  std::vector<PendingCommand> waiting_;  // taken, awaiting the rig's confirmation (acquisition thread only)
  RigSupervision snap_;
  void carry_out(PendingCommand c, double t);
  bool settled(const PendingCommand& c);  // answered (and to be dropped)
  void answer(const PendingCommand& c, CommandOutcome::Result r, const std::string& reason);
};

// One period between campaigns: the stop channel, one supervised read shown live (the simulator
// restarted if it died), the channel again (what the read confirmed is answered at once). t: rig
// seconds; host_s: the host's monotonic seconds (the heartbeat's clock).
void idle_tick(RigWorker& w, double t, const std::string& base, double host_s);
void idle_step(RigWorker& w, double t, const std::string& base, double host_s);
// The acquisition thread's error boundary: an exception escaped a campaign or a tick. The rig is
// held (disarmed), the running campaign failed with the reason, and the thread goes on.
void contain(RigWorker& w, db::SampleWriter& writer, const std::string& what, double t);

// The rig's acquisition thread: operator commands first, then queued campaigns in order; between
// them the rig is sampled every 50 ms (supervised, shown live). Every exception is caught here:
// the rig is held, the campaign failed with the reason, and the thread goes on.
// Work leaves the thread through `offload`: the ends of runs and the evaluations during them.
struct Offload {
  std::function<void(FinishJob)> finish;
  std::function<void(std::function<void()>)> background;
};
void rig_thread(RigWorker& w, db::SampleWriter& writer, const Offload& offload, const std::atomic<bool>& stop, const std::string& base);

}  // namespace hystlab::daemon
