// The daemon as other threads (HTTP) see it: its snapshots, the rig a plan runs on, submissions,
// a campaign's record, and operator commands to campaigns and rigs.
#include <chrono>
#include <cstdint>
#include <future>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "daemon_impl.hpp"
#include "hystlab/daemon/daemon.hpp"
#include "hystlab/db/campaign_record.hpp"
#include "hystlab/domain/plan.hpp"
#include "monotonic_clock.hpp"
#include "rig_worker.hpp"

namespace hystlab::daemon {

const DaemonConfig& Daemon::config() const noexcept { return impl_->config; }
double Daemon::rig_time_scale(std::size_t k) const { return impl_->workers.at(k)->entry.time_scale; }
std::size_t Daemon::rig_count() const noexcept { return impl_->workers.size(); }
const RigInfo& Daemon::rig_info(std::size_t k) const { return impl_->workers.at(k)->info; }
const RigLive& Daemon::rig_live(std::size_t k) const { return impl_->workers.at(k)->live; }
drivers::IoHealthSnapshot Daemon::rig_health(std::size_t k) const { return impl_->workers.at(k)->rig->health(); }
RigSupervision Daemon::rig_supervision(std::size_t k) const { return impl_->workers.at(k)->snapshot(); }
db::WriterStats Daemon::writer_stats() const { return impl_->writer->stats(); }
double Daemon::uptime_s() const noexcept { return std::chrono::duration<double>(std::chrono::steady_clock::now() - impl_->started).count(); }

// Without a name: the only rig, or the only one of the kind the plan needs (the embedded
// defaults have a load frame and a shaker, and a FOT plan can only mean the frame).
std::size_t Daemon::rig_index(const std::string& name, std::string_view plan_kind) const {
  const auto& ws = impl_->workers;
  std::string names;
  for (const auto& w : ws) names += (names.empty() ? "'" : ", '") + w->info.name + "' (" + domain::to_string(w->info.kind) + ")";
  if (name.empty()) {
    if (ws.size() == 1) return 0;
    const std::optional<domain::RigKind> want =
        plan_kind.empty() ? std::nullopt : std::optional(plan_kind == "sine" ? domain::RigKind::shaker : domain::RigKind::load_frame);
    std::vector<std::size_t> fit;
    for (std::size_t k = 0; k < ws.size(); ++k)
      if (want && ws[k]->info.kind == *want) fit.push_back(k);
    if (fit.size() == 1) return fit[0];
    throw std::invalid_argument("rig: several rigs " + (want ? "can run a " + std::string(plan_kind) + " plan" : std::string("are configured")) + " (" + names +
                                "); name one with \"rig\" (--rig NAME)");
  }
  for (std::size_t k = 0; k < ws.size(); ++k)
    if (ws[k]->info.name == name) return k;
  throw std::invalid_argument("rig: no rig named '" + name + "' (the rigs: " + names + ")");
}

std::pair<domain::Plan, std::size_t> Daemon::check_plan(const std::string& rig_name, const json& plan_json) const {
  domain::Plan plan = domain::parse_plan(plan_json);  // PlanError names the field
  const std::size_t k = rig_index(rig_name, domain::to_string(plan.kind));
  const RigWorker& rig = *impl_->workers.at(k);
  const bool shaker = rig.info.kind == domain::RigKind::shaker;
  if ((plan.kind == domain::CampaignKind::sine) != shaker)
    throw std::invalid_argument(std::string("plan.kind: a ") + domain::to_string(plan.kind) + " plan cannot run on rig '" + rig.info.name + "', a " +
                                domain::to_string(rig.info.kind));
  (void)domain::check_plan_against(plan, rig.entry.envelope, rig.entry.supervision, shaker);  // PlanError names the field
  return {std::move(plan), k};
}

domain::Limits Daemon::applied_limits(const domain::Plan& plan, std::size_t k) const {
  const RigWorker& rig = *impl_->workers.at(k);
  return domain::check_plan_against(plan, rig.entry.envelope, rig.entry.supervision, rig.info.kind == domain::RigKind::shaker);
}

std::int64_t Daemon::submit(const std::string& rig_name, const json& plan_json) {
  const double called = mono_now();  // for the submission latency (RigLive::submit_latency_s)
  const auto [plan, k] = check_plan(rig_name, plan_json);
  RigWorker& rig = *impl_->workers.at(k);
  if (const RigSupervision s = rig.snapshot(); s.latched)
    throw std::invalid_argument("rig: '" + rig.info.name + "' is " + s.state + " (" + s.latch_reason + "): reset it first");
  const std::int64_t rig_id = rig.info.id;
  const domain::CampaignKind kind = plan.kind;
  const std::string text = plan_json.dump();
  domain::Plan checked = plan;
  checked.limits = applied_limits(plan, k);
  // On the main loop: the row first (the record), then the parsed job straight to the rig.
  return impl_->on_main<std::int64_t>([this, rig_id, kind, text, &rig, called, checked = std::move(checked)]() mutable {
    auto isolator = impl_->isolator_for(rig, checked);  // before the row: a plan whose table is not there is refused
    const std::int64_t id = impl_->store.create_campaign(rig_id, kind, text, now_iso());
    impl_->dispatch_new(rig, id, std::move(checked), called, std::move(isolator));
    return id;
  });
}

void Daemon::set_record(std::int64_t campaign_id, const json& changes) {
  if (!changes.is_object() || changes.empty()) throw control::PlanError("", "record: give the specimen, the notes or both");
  for (const auto& [field, value] : changes.items()) {
    const auto problem =
        value.is_string() ? domain::record_field_problem(field, value.get<std::string>()) : domain::record_field_problem(field, "").value_or("must be text");
    if (problem) throw control::PlanError(field, field + " " + *problem);
  }
  impl_->on_main<bool>([this, campaign_id, changes] {
    auto& store = impl_->store;
    const auto row = store.campaign(campaign_id);
    if (!row) throw std::out_of_range("campaign " + std::to_string(campaign_id) + " does not exist");
    db::CampaignRecord r = db::campaign_record(store, *row);
    if (changes.contains("specimen")) r.specimen = changes["specimen"].get<std::string>();
    if (changes.contains("notes")) r.notes = changes["notes"].get<std::string>();
    (void)store.add_event(campaign_id, domain::RecordEvent{r.specimen, r.notes}, now_iso());
    return true;
  });
}

CommandOutcome Daemon::command(std::int64_t campaign_id, CampaignCommand cmd) {
  auto& d = *impl_;
  if (cmd == CampaignCommand::estop) {  // the rig first, latched and confirmed; the campaign ends by the latch
    RigWorker* w = d.rig_of_campaign(campaign_id);
    if (!w)
      w = d.on_main<RigWorker*>([&d, campaign_id]() -> RigWorker* {
        const auto row = d.store.campaign(campaign_id);
        return row && !domain::is_final(row->state) ? d.worker_of(row->rig_id) : nullptr;
      });
    if (w) {
      CommandOutcome rig = d.rig_command(*w, RigCommand::estop, 2.0);
      if (w->running_campaign != campaign_id)  // not running: the record ends here (running: the latch ended it)
        (void)d.on_main<CommandOutcome>([&d, campaign_id] { return d.route(campaign_id, CampaignCommand::abort); });
      else
        d.direct(campaign_id, cmd);  // the command is recorded with the campaign
      return rig;
    }
  }
  if (d.direct(campaign_id, cmd)) return {CommandOutcome::Result::pending, false, false, "running", "taken by the running campaign", 0};
  return d.on_main<CommandOutcome>([&d, campaign_id, cmd] { return d.route(campaign_id, cmd); });
}

CommandOutcome Daemon::rig_command(std::size_t rig, RigCommand c, double wait_s) { return impl_->rig_command(*impl_->workers.at(rig), c, wait_s); }

CommandOutcome Daemon::Impl::rig_command(RigWorker& w, RigCommand c, double wait_s) {
  std::future<CommandOutcome> answer = w.push_rig_command(c);
  // The rig's thread takes it at its next period (1 ms at 1 kHz, 50 ms between campaigns) and
  // answers once the rig's status word confirms it. A thread stuck in I/O answers late: the
  // caller then hears what is known, never silence. A latch is on the host at once either way.
  if (answer.wait_for(std::chrono::duration<double>(wait_s)) == std::future_status::ready) {
    try {
      return answer.get();
    } catch (const std::future_error&) {  // the thread ended (the daemon is stopping)
    }
  }
  const RigSupervision s = w.snapshot();
  return {CommandOutcome::Result::pending,
          s.latched,
          false,
          s.state,
          "the rig's thread has not confirmed it within " + std::to_string(wait_s).substr(0, 3) + " s",
          wait_s};
}

}  // namespace hystlab::daemon
