#include "rig_worker.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstring>
#include <ctime>

#include "hystlab/drivers/rig_factory.hpp"
#include "hystlab/protocols/signals.hpp"
#include "monotonic_clock.hpp"

namespace hystlab::daemon {
using nlohmann::json;

void RigWorker::build_rig(const std::string& base) {
  json cfg = entry.driver;
  if (entry.simulated) {
    if (!sim) sim = std::make_unique<SimChild>(entry.sim);
    // In real time the simulated controller is read as a real one is best read: in blocks from its
    // own sample buffer. Faster than real time its clock outruns any reader; the latest value then.
    cfg = json{{"name", entry.name},   {"transport", "modbus-tcp"},
               {"host", "127.0.0.1"},  {"port", sim->ensure_running()},
               {"rig", entry.sim.rig}, {"block_reads", entry.sim.time_scale <= 1}};
    entry.time_scale = entry.sim.time_scale;
  }
  cfg["name"] = entry.name;
  rig = drivers::make_rig(cfg, "rig '" + entry.name + "'", base);
  info.name = entry.name;
  info.simulated = entry.simulated;
  const auto kind = domain::rig_kind_from(cfg.value("rig", std::string("load_frame")));  // make_rig refused any other
  if (!kind) throw ConfigError("rig '" + entry.name + "': rig must be \"load_frame\" or \"shaker\"");
  info.kind = *kind;
  info.description = rig->describe();
  const bool shaker = info.kind == domain::RigKind::shaker;
  if (supervisor)
    supervisor->rebind(*rig);
  else
    supervisor = std::make_unique<Supervisor>(*rig, entry.supervision, shaker, [this](const RigTransition& t) { record(t); });
  supervisor->set_time_scale(entry.time_scale);
  std::lock_guard lk(mu_);
  snap_.envelope = domain::envelope_json(entry.envelope, shaker);
  snap_.supervision = domain::supervision_json(entry.supervision);
}

namespace {
template <class T>
void push_locked(std::mutex& mu, std::condition_variable& cv, std::deque<T>& q, T item) {
  {
    std::lock_guard lk(mu);
    q.push_back(std::move(item));
  }
  cv.notify_all();
}
template <class T>
std::optional<T> pop_locked(std::mutex& mu, std::deque<T>& q) {
  std::lock_guard lk(mu);
  if (q.empty()) return std::nullopt;
  T item = std::move(q.front());
  q.pop_front();
  return item;
}
}  // namespace

void RigWorker::push_job(CampaignJob job) { push_locked(mu_, cv_, jobs_, std::move(job)); }
void RigWorker::push_control(Control c) { push_locked(mu_, cv_, controls_, c); }
std::future<CommandOutcome> RigWorker::push_rig_command(RigCommand c) {
  PendingCommand p{c, std::make_shared<std::promise<CommandOutcome>>(), mono_now()};
  auto fut = p.answer->get_future();
  push_locked(mu_, cv_, rig_commands_, std::move(p));
  return fut;
}
bool RigWorker::cancel_queued(std::int64_t id) {
  std::lock_guard lk(mu_);
  for (auto it = jobs_.begin(); it != jobs_.end(); ++it)
    if (it->id == id) {
      jobs_.erase(it);
      return true;
    }
  return false;
}
bool RigWorker::has_queued(std::int64_t id) {
  std::lock_guard lk(mu_);
  for (const auto& j : jobs_)
    if (j.id == id) return true;
  return running_campaign == id;
}
std::optional<CampaignJob> RigWorker::pop_job() {
  std::lock_guard lk(mu_);
  if (jobs_.empty()) return std::nullopt;
  CampaignJob j = std::move(jobs_.front());
  jobs_.pop_front();
  running_campaign = j.id;  // under the lock: a command sees it queued or running, never neither
  controls_.clear();        // commands meant for an earlier campaign
  return j;
}
std::optional<Control> RigWorker::pop_control() { return pop_locked(mu_, controls_); }

void RigWorker::answer(const PendingCommand& c, CommandOutcome::Result r, const std::string& reason) {
  CommandOutcome o;
  o.result = r;
  o.latched = supervisor->latched();
  o.confirmed = r == CommandOutcome::Result::done;
  o.state = std::string(to_string(supervisor->state()));
  o.reason = reason;
  o.waited_s = mono_now() - c.asked_mono;
  try {
    c.answer->set_value(std::move(o));
  } catch (const std::future_error&) {  // answered already
  }
}

// An e-stop is written at once from any state; a reset applies only to a latched rig (while a
// campaign moves the rig nothing is latched, and the controller's reset is not written then).
void RigWorker::carry_out(PendingCommand c, double t) {
  using R = CommandOutcome::Result;
  Supervisor& sup = *supervisor;
  if (c.command == RigCommand::estop) {
    if (const std::error_code ec = sup.estop(t, "e-stop by the operator")) {
      answer(c, R::unreachable,
             "the rig did not take the e-stop (" + ec.message() + "): latched here, nothing arms, and the e-stop is written again the moment the rig answers");
      return;
    }
    waiting_.push_back(std::move(c));
    return;
  }
  if (c.command == RigCommand::recover) {
    if (running_campaign) return answer(c, R::conflict, "a campaign is running on the rig");
    if (auto why = sup.begin_recovery(t, entry.envelope.stroke_min_mm, entry.envelope.stroke_max_mm)) return answer(c, R::conflict, *why);
    waiting_.push_back(std::move(c));
    return;
  }
  if (sup.recovering()) return answer(c, R::conflict, "the frame is being brought back into its stroke (an e-stop stops it)");
  if (!sup.latched()) {
    answer(c, R::conflict, "the rig is " + std::string(to_string(sup.state())) + ", not latched: there is nothing to reset");
    return;
  }
  sup.begin_reset(t);
  if (!sup.resetting()) return answer(c, R::unreachable, sup.reset_refusal());
  waiting_.push_back(std::move(c));
}

bool RigWorker::settled(const PendingCommand& c) {
  using R = CommandOutcome::Result;
  const Supervisor& sup = *supervisor;
  if (c.command == RigCommand::estop) {
    if (sup.state() != RigState::estopped) return answer(c, R::done, "latched, then reset"), true;
    if (!sup.estop_confirmed()) return false;
    answer(c, R::done, "latched: the rig reports its e-stop");
    return true;
  }
  if (c.command == RigCommand::recover) {
    if (sup.recovering()) return false;
    // Refused when it was stopped on the way, latched or not (a frame left outside the configured
    // stroke is not latched, and its recovery can still be stopped).
    answer(c, sup.recovered() ? R::done : R::refused, sup.recovery_result());
    return true;
  }
  if (sup.resetting()) return false;
  if (!sup.latched()) return answer(c, R::done, "reset: the rig reports ready"), true;
  std::string why = sup.reset_refusal().empty() ? "the rig is still latched" : sup.reset_refusal();
  if (info.kind != domain::RigKind::shaker && (sup.last_status().status & protocols::status::limit_tripped))
    why += "; a frame beyond its stroke is brought back with POST /api/rigs/NAME/recover (hystlab rig recover)";
  answer(c, R::refused, why);
  return true;
}

void RigWorker::service(double t) {
  std::erase_if(waiting_, [this](const PendingCommand& c) { return settled(c); });
  for (;;) {
    std::optional<PendingCommand> c = pop_locked(mu_, rig_commands_);
    if (!c) break;
    carry_out(std::move(*c), t);
  }
  // An answer nobody confirms (a rig that takes writes and never reports): the asker has long
  // had its bounded wait; the entry is dropped so that waiting_ stays bounded.
  const double now = mono_now();
  std::erase_if(waiting_, [&](const PendingCommand& c) {
    if (now - c.asked_mono < 30.0) return false;
    answer(c, CommandOutcome::Result::pending, "not confirmed by the rig within 30 s");
    return true;
  });
}
void RigWorker::wait(double seconds) {
  std::unique_lock lk(mu_);
  cv_.wait_for(lk, std::chrono::duration<double>(seconds), [this] { return !jobs_.empty() || !rig_commands_.empty(); });
}

void RigWorker::record(const RigTransition& t) {
  const bool bad = t.to == RigState::estopped || t.to == RigState::faulted || t.to == RigState::disconnected;
  spdlog::log(bad ? spdlog::level::warn : spdlog::level::info, "rig '{}': {} -> {}: {}", entry.name, to_string(t.from), to_string(t.to), t.reason);
  std::lock_guard lk(mu_);
  snap_.state = std::string(to_string(t.to));
  snap_.latched = t.to == RigState::estopped || t.to == RigState::faulted;
  if (snap_.latched) snap_.latch_reason = t.reason;
  snap_.recent.push_back({{"at", now_iso()}, {"t", t.t}, {"from", to_string(t.from)}, {"to", to_string(t.to)}, {"reason", t.reason}});
  if (snap_.recent.size() > 50) snap_.recent.erase(snap_.recent.begin());
  ++snap_.transitions;
}

void RigWorker::update_snapshot(const StatusView& v, double x, double f, bool have) {
  const Supervisor& s = *supervisor;
  const std::string text = v.fault_code ? rig->fault_text(v.fault_code) : std::string();
  std::lock_guard lk(mu_);
  snap_.state = std::string(to_string(s.state()));
  snap_.latched = s.latched();
  snap_.latch_reason = s.latch_reason();
  snap_.latched_fault_code = s.fault_code();
  snap_.resetting = s.resetting();
  snap_.reset_refusal = s.reset_refusal();
  snap_.recovering = s.recovering();
  snap_.recovery_result = s.recovery_result();
  snap_.link_losses = s.link_losses();
  if (!have) return;
  snap_.have_sample = true;
  snap_.status_word = v.status;
  snap_.fault_code = v.fault_code;
  snap_.fault_text = text;
  snap_.position_mm = x;
  snap_.force_N = f;
}

RigSupervision RigWorker::snapshot() const {
  std::lock_guard lk(mu_);
  return snap_;
}

namespace {

void run_job(RigWorker& w, CampaignJob job, db::SampleWriter& writer, const Offload& offload, const std::atomic<bool>& stop, double epoch) {
  SteadyClock clock;
  RunnerContext ctx(*w.rig, *w.supervisor, writer, clock);
  ctx.time_scale = w.entry.time_scale;
  ctx.stop = &stop;
  ctx.now_iso = now_iso;
  ctx.next_control = [&w] { return w.pop_control(); };
  ctx.service = [&w](double t) { w.service(t); };
  ctx.live = &w.live;
  ctx.finish = offload.finish;
  ctx.background = offload.background;
  ctx.epoch = epoch;
  const auto id = job.id;
  ctx.on_state = [&w, id](const std::string& s) { spdlog::info("rig '{}': campaign {} {}", w.entry.name, id, s); };
  w.live.sample_rate_hz = job.plan.sample_rate_hz;
  w.live.campaign = id;
  const RunnerResult r = run_campaign(job, ctx);
  w.live.campaign = 0;
  spdlog::info("rig '{}': campaign {} ended {} ({} samples, {} missed deadlines, {} late wake-ups, {} gaps, {} dropped){}{}", w.entry.name, id,
               to_string(r.end), r.samples, r.missed_deadlines, r.late_wakeups, r.gaps, r.dropped, r.reason.empty() ? "" : ": ", r.reason);
}

constexpr int kIdleMissesForLinkLoss = 3;  // 150 ms of 50 ms idle ticks, plus the read timeouts

}  // namespace

// Between campaigns: one supervised read, shown live (run 0); the simulator restarted if it died.
void idle_tick(RigWorker& w, double t, const std::string& base, double host_s) {
  if (w.sim && !w.sim->alive()) {
    spdlog::warn("rig '{}': the simulator died; starting a new one", w.entry.name);
    w.build_rig(base);
  }
  StatusView v;
  double x = 0, f = 0;
  std::error_code ec;
  if (w.info.kind == domain::RigKind::shaker) {
    drivers::ShakerSample s;
    ec = w.rig->read_shaker(t, s);
    v = {s.status_word, s.fault_code, 0.0};
    x = s.mass_displacement_mm, f = s.mass_accel_m_s2;
    if (!ec)
      w.live.ring.push(LiveSample::of(mono_now(), t, domain::LiveShaker{s.base_displacement_mm, s.mass_displacement_mm, s.mass_accel_m_s2}, 0, s.status_word));
  } else {
    drivers::RigSample s;
    ec = w.rig->read_sample(t, s);
    v = {s.status_word, s.fault_code, s.displacement_mm};
    x = s.displacement_mm, f = s.force_N;
    if (!ec) w.live.ring.push(LiveSample::of(mono_now(), t, domain::FrameSample{s.command_mm, s.displacement_mm, s.force_N}, 0, s.status_word));
  }
  // The link is lost when the connection is, or after kIdleMissesForLinkLoss failed reads in a
  // row: one late answer is no lost link (a starved CI host timed out a read every few seconds,
  // and the rig flapped between idle and disconnected, holding it each time).
  const bool gone = ec == drivers::RigError::connection_lost || ec == drivers::RigError::not_connected;
  if (!ec)
    w.idle_misses = 0, (void)w.supervisor->on_status(t, v);
  else if (gone || ++w.idle_misses >= kIdleMissesForLinkLoss)
    w.supervisor->on_link_error(t, ec);
  w.supervisor->heartbeat(host_s);
  w.update_snapshot(v, x, f, !ec);
}

void idle_step(RigWorker& w, double t, const std::string& base, double host_s) {
  w.service(t);
  idle_tick(w, t, base, host_s);
  w.service(t);  // what this read confirmed is answered now, not a wait later
}

// An exception escaped a campaign or a tick: hold the rig, fail the campaign, keep the thread.
void contain(RigWorker& w, db::SampleWriter& writer, const std::string& what, double t) {
  spdlog::error("rig '{}': {}: rig held", w.entry.name, what);
  try {
    if (w.supervisor) w.supervisor->disarm(t, "error on the acquisition thread: " + what);
  } catch (...) {  // nothing more to do here; the next tick re-asserts the hold
  }
  if (const std::int64_t id = w.running_campaign.exchange(0)) {
    const std::string now = now_iso(), reason = "error on the acquisition thread: " + what + "; the rig is held";
    writer.post([id, reason, now](db::Store& s) { s.transition(id, domain::CampaignState::failed, reason, now); });
  }
  w.live.campaign = 0;
  w.live.phase = 0;
}

void rig_thread(RigWorker& w, db::SampleWriter& writer, const Offload& offload, const std::atomic<bool>& stop, const std::string& base) {
  // Ahead of everything else in the process when the system allows it; otherwise it says so once.
  spdlog::info("rig '{}': acquisition thread at {}", w.entry.name, enter_acquisition_thread(w.acquisition));
  const double t0 = mono_now();
  auto rig_time = [&] { return (mono_now() - t0) * w.entry.time_scale; };
  (void)w.rig->connect(0.0);
  while (!stop) {
    try {
      w.service(rig_time());
      if (auto job = w.pop_job()) {
        if (job->submitted_mono > 0) w.live.submit_latency_s = mono_now() - job->submitted_mono;
        run_job(w, std::move(*job), writer, offload, stop, t0);
        w.idle_misses = 0;
        w.running_campaign = 0;
        continue;
      }
      idle_step(w, rig_time(), base, mono_now());
      w.wait(0.05);
    } catch (const std::exception& e) {
      contain(w, writer, e.what(), rig_time());
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    } catch (...) {
      contain(w, writer, "unknown exception", rig_time());
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  try {
    w.supervisor->disarm(rig_time(), "the daemon is stopping");
  } catch (...) {  // stopping anyway
  }
}

}  // namespace hystlab::daemon
