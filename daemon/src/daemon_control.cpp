#include "hystlab/daemon/daemon_control.hpp"

#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/daemon/plan_preview.hpp"

namespace hystlab::daemon {
namespace {

// drivers::RigError's values, as the API and /metrics name them (index = the enum's value).
constexpr const char* kErrorNames[] = {
    "", "timeout", "exception_response", "connection_lost", "crc_error", "out_of_range", "protocol_error", "not_connected", "stale_data", "unsupported"};
static_assert(sizeof kErrorNames / sizeof kErrorNames[0] == drivers::kRigErrorCount);

control::LinkHealth link_health(const drivers::IoHealthSnapshot& h) {
  control::LinkHealth out;
  out.reads = h.reads;
  out.writes = h.writes;
  out.reconnects = h.reconnects;
  out.lost_samples = h.lost_samples;
  for (std::size_t k = 1; k < drivers::kRigErrorCount; ++k) out.errors.emplace_back(kErrorNames[k], h.errors[k]);
  out.last_transaction_us = h.last_transaction_us;
  out.max_transaction_us = h.max_transaction_us;
  out.total_transaction_us = h.total_transaction_us;
  out.latency_histogram_us.assign(h.latency_histogram.begin(), h.latency_histogram.end());
  return out;
}

class DaemonControl final : public control::DaemonInterface {
 public:
  explicit DaemonControl(Daemon& d) : d_(d) {}

  std::size_t rig_count() const noexcept override { return d_.rig_count(); }
  control::RigInfo rig_info(std::size_t k) const override { return d_.rig_info(k); }
  control::RigSupervision rig_supervision(std::size_t k) const override { return d_.rig_supervision(k); }
  control::LinkHealth rig_health(std::size_t k) const override { return link_health(d_.rig_health(k)); }
  control::AcquisitionCounters rig_counters(std::size_t k) const override {
    const RigLive& live = d_.rig_live(k);
    return {live.samples.load(),
            live.missed_deadlines.load(),
            live.late_wakeups.load(),
            live.campaign.load(),
            live.run.load(),
            live.sample_rate_hz.load(),
            to_string(static_cast<CampaignPhase>(live.phase.load())),
            live.submit_latency_s.load()};
  }
  std::size_t rig_index(const std::string& name, std::string_view plan_kind) const override { return d_.rig_index(name, plan_kind); }
  // A recovery ramps the frame at the safe rate (a few seconds): its answer waits for the outcome.
  control::CommandOutcome rig_command(std::size_t k, control::RigCommand c) override {
    return d_.rig_command(k, c, c == control::RigCommand::recover ? 25.0 : 2.0);
  }

  std::uint64_t live_head(std::size_t k) const noexcept override { return k < d_.rig_count() ? d_.rig_live(k).ring.head() : 0; }
  std::uint64_t read_live(std::size_t k, std::uint64_t from, std::size_t stride, std::vector<control::LiveSample>& out, std::uint64_t* lost) const override {
    return d_.rig_live(k).ring.read(from, stride, out, lost);
  }

  std::int64_t submit(const std::string& rig, const nlohmann::json& plan) override { return d_.submit(rig, plan); }
  control::PlanPreview preview(const std::string& rig, const nlohmann::json& plan, models::HysteresisModel* model) const override {
    const auto [p, k] = d_.check_plan(rig, plan);
    control::PlanPreview v = preview_plan(p, model);
    v.time_scale = d_.rig_time_scale(k);
    v.limits_applied = domain::limits_tightened(p, d_.applied_limits(p, k));
    return v;
  }
  control::CommandOutcome command(std::int64_t campaign, control::CampaignCommand c) override { return d_.command(campaign, c); }
  void set_record(std::int64_t campaign, const nlohmann::json& changes) override { d_.set_record(campaign, changes); }

  control::WriterCounters writer() const override {
    const db::WriterStats w = d_.writer_stats();
    return {w.written, w.depth, w.dropped_full, w.commits};
  }
  double uptime_s() const noexcept override { return d_.uptime_s(); }
  std::string db_path() const override { return d_.config().db_path; }
  void keep_off_acquisition_cpu(bool off) const noexcept override { (void)avoid_cpu(off ? resolve_cpu(d_.config().acquisition.cpu) : -1); }

 private:
  Daemon& d_;
};

}  // namespace

std::unique_ptr<control::DaemonInterface> make_control(Daemon& d) { return std::make_unique<DaemonControl>(d); }

}  // namespace hystlab::daemon
