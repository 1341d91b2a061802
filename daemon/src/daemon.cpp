#include "hystlab/daemon/daemon.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <filesystem>
#include <future>
#include <limits>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "finisher.hpp"
#include "hystlab/db/campaign_record.hpp"
#include "hystlab/domain/plan.hpp"
#include "hystlab/drivers/rig_factory.hpp"
#include "monotonic_clock.hpp"
#include "resume_loader.hpp"
#include "rig_worker.hpp"

namespace hystlab::daemon {
using nlohmann::json;

struct Daemon::Impl {
  DaemonConfig config;
  db::Store store;  // the main loop's connection
  std::vector<std::unique_ptr<RigWorker>> workers;
  std::unique_ptr<db::SampleWriter> writer;
  std::unique_ptr<Finisher> finisher;
  std::unique_ptr<ResumeLoader> loader;  // resumed campaigns' earlier samples, read off the main loop
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
  std::mutex mu;
  std::condition_variable cv;
  std::deque<std::function<void()>> jobs;  // from other threads, run by the main loop
  bool accepting = true;
  std::set<std::int64_t> dispatched;  // campaigns handed to a rig's thread (main loop only)
  // Campaigns handed to the finisher and not yet finished: their rig is idle, their record still
  // says running; a command to one is refused (an abort there was stored, then overwritten by
  // the finisher's end).
  std::mutex finishing_mu;
  std::set<std::int64_t> finishing;
  bool being_finished(std::int64_t id) {
    std::lock_guard lk(finishing_mu);
    return finishing.count(id) > 0;
  }
  double db_backoff_s = 0;  // a busy or failing database: retried, reported once per episode
  bool redispatch = true;   // queued rows to hand over (start-up, a resume, a failed pass)

  explicit Impl(const DaemonConfig& c) : config(c), store(c.db_path) {}

  // Runs f on the main loop with its store and waits for it (at most 10 s). An exception crosses
  // as an exception_ptr that the caller moves out of the answer, so the caller's thread holds its
  // only reference and frees it. (A std::packaged_task left a reference in the job, freed by the
  // main loop while the HTTP thread still read the message: ThreadSanitizer saw that race in CI,
  // since libstdc++'s exception refcount is not instrumented.)
  template <class R>
  R on_main(std::function<R()> f) {
    struct Answer {
      std::mutex m;
      std::condition_variable cv;
      bool done = false;
      std::optional<R> value;
      std::exception_ptr error;
    };
    auto answer = std::make_shared<Answer>();
    {
      std::lock_guard lk(mu);
      if (!accepting) throw std::runtime_error("the daemon is stopping");
      jobs.emplace_back([answer, f = std::move(f)] {
        std::optional<R> value;
        std::exception_ptr error;
        try {
          value.emplace(f());
        } catch (...) {
          error = std::current_exception();
        }
        std::lock_guard alk(answer->m);
        if (value) answer->value.emplace(std::move(*value));  // R need not be assignable
        answer->error = std::move(error);
        answer->done = true;
        answer->cv.notify_all();
      });
    }
    cv.notify_one();
    std::unique_lock lk(answer->m);
    if (!answer->cv.wait_for(lk, std::chrono::seconds(10), [&] { return answer->done; }))
      throw std::runtime_error("the daemon did not answer within 10 s (is the database busy?)");
    if (std::exception_ptr error = std::move(answer->error)) {
      lk.unlock();
      std::rethrow_exception(std::move(error));
    }
    return std::move(*answer->value);
  }

  RigWorker* worker_of(std::int64_t rig_id) {
    for (auto& w : workers)
      if (w->info.id == rig_id) return w.get();
    return nullptr;
  }

  // A campaign's command that its rig's thread carries out now; false when it is not running.
  bool direct(std::int64_t campaign, CampaignCommand cmd) {
    const std::string verb = to_string(cmd);
    const Control c = cmd;
    for (auto& w : workers)
      if (w->running_campaign == campaign) {
        w->push_control(c);
        const std::string now = now_iso();
        writer->post([campaign, verb, now](db::Store& s) { s.add_event(campaign, domain::CommandEvent{verb}, now); });
        return true;
      }
    return false;
  }

  // An operator command that found no running campaign: the main loop, with the database.
  CommandOutcome route(std::int64_t campaign, CampaignCommand cmd) {
    using R = CommandOutcome::Result;
    if (direct(campaign, cmd)) return {R::pending, false, false, "running", "taken by the running campaign", 0};
    const auto row = store.campaign(campaign);
    if (!row) return {R::conflict, false, false, "", "no campaign " + std::to_string(campaign), 0};
    if (being_finished(campaign))
      return {R::conflict,
              false,
              false,
              "finishing",
              "campaign " + std::to_string(campaign) + " no longer moves the rig: its tables are being built, '" + to_string(cmd) + "' does not apply",
              0};
    using C = CampaignCommand;
    using S = domain::CampaignState;
    RigWorker* w = worker_of(row->rig_id);
    const std::string state = domain::to_string(row->state);
    if (cmd == C::resume && (row->state == S::interrupted || row->state == S::paused || row->state == S::held)) {
      dispatched.erase(campaign);
      store.transition(campaign, S::queued,
                       row->state == S::held ? "released by the operator" : "re-queued to resume: wipe-out preamble, then the rows not yet measured",
                       now_iso());
      redispatch = true;  // to its rig on this loop's next pass (its earlier samples read there, not in this call)
      return {R::done, false, false, "queued", "queued to resume", 0};
    }
    if ((cmd == C::abort || cmd == C::estop) && !domain::is_final(row->state)) {
      if (w && w->has_queued(campaign) && !w->cancel_queued(campaign)) {  // it just started: stop it there
        (void)direct(campaign, cmd);
        return {R::pending, false, false, "running", "taken by the campaign that had just started", 0};
      }
      const std::string why = std::string(cmd == C::estop ? "e-stop" : "aborted") + " by the operator while " + state;
      store.transition(campaign, S::aborted, why, now_iso());
      return {R::done, false, false, "aborted", why, 0};
    }
    const std::string why = "campaign " + std::to_string(campaign) + " is " + state + ": '" + to_string(cmd) + "' does not apply";
    store.add_event(campaign, domain::CommandEvent{std::string("'") + to_string(cmd) + "' refused: the campaign is " + state}, now_iso());
    return {R::conflict, false, false, state, why, 0};
  }

  // The rig's command through its stop channel, answered once confirmed (or after wait_s).
  CommandOutcome rig_command(RigWorker& w, RigCommand c, double wait_s);

  // The rig a campaign runs on (or is queued for); nullptr when unknown.
  RigWorker* rig_of_campaign(std::int64_t campaign) {
    for (auto& w : workers)
      if (w->running_campaign == campaign || w->has_queued(campaign)) return w.get();
    return nullptr;
  }

  // The envelope in force when the campaign was handed to its rig (the HDF5 export's
  // /campaign/envelope): the rig's config row is rewritten at every start and holds none. A
  // record, not a condition of the run: a busy database here never keeps a job from its rig.
  void record_envelope(const RigWorker& w, std::int64_t id) noexcept {
    try {
      store.add_event(id, domain::envelope_event(w.entry.envelope, w.info.kind == domain::RigKind::shaker), now_iso());
    } catch (const std::exception& e) {
      spdlog::warn("campaign {}: the envelope in force was not recorded ({})", id, e.what());
    }
  }

  // A campaign just submitted: its plan, parsed once by submit() and checked against the rig's
  // envelope, goes to the rig's thread as it is (no second parse, no database round trip: the
  // row is the record, and the source only at a restart or a resume).
  void dispatch_new(RigWorker& w, std::int64_t id, domain::Plan plan, double submitted_mono, std::shared_ptr<const IsolatorModel> isolator) {
    CampaignJob job;
    job.isolator = std::move(isolator);
    job.id = id;
    job.submitted_mono = submitted_mono;
    job.plan = std::move(plan);
    dispatched.insert(id);
    w.push_job(std::move(job));
    record_envelope(w, id);
  }

  // Hands queued campaigns to their rigs' threads, once each, with the plan checked against the
  // rig's envelope and what earlier runs measured: at start-up, on a resume, and again after a
  // pass the database refused (redispatch).
  void dispatch() {
    for (auto& w : workers)
      for (const std::int64_t id : store.queued_campaigns(w->info.id)) {
        if (dispatched.count(id)) continue;
        dispatched.insert(id);
        std::optional<CampaignJob> job;
        try {
          job = make_job(*w, id);
        } catch (...) {  // the database refused: handed over again on a later pass, not forgotten
          dispatched.erase(id);
          throw;
        }
        if (job) w->push_job(std::move(*job));
      }
  }

  // The isolator a sine campaign is predicted with: its plan's own (a stored table by id, read
  // here on the main loop), else the rig's. A plan's that cannot be built is the plan's error.
  std::shared_ptr<const IsolatorModel> isolator_for(const RigWorker& w, const domain::Plan& plan) {
    if (plan.kind != domain::CampaignKind::sine || plan.sine.isolator.is_null()) return w.entry.isolator;
    try {
      return std::make_shared<const IsolatorModel>(parse_isolator(
          plan.sine.isolator, "isolator", [this](std::int64_t t) { return store.table_document(t); }, w.entry.isolator.get()));
    } catch (const IsolatorError& e) {
      throw control::PlanError(e.field, e.what());
    }
  }

  std::optional<CampaignJob> make_job(RigWorker& w, std::int64_t id) {
    const auto row = store.campaign(id);
    if (!row) return std::nullopt;
    CampaignJob job;
    job.id = id;
    try {
      job.plan = domain::parse_plan(json::parse(row->plan));
      job.plan.limits = domain::check_plan_against(job.plan, w.entry.envelope, w.entry.supervision, w.info.kind == domain::RigKind::shaker);
      job.isolator = isolator_for(w, job.plan);
    } catch (const std::exception& e) {  // a plan stored by an older or foreign tool: fail it, say why
      store.transition(id, domain::CampaignState::failed, e.what(), now_iso());
      return std::nullopt;
    }
    record_envelope(w, id);
    for (const auto& [a, b, fa, fab] : store.fot_nodes_of_campaign(id)) job.prior_nodes.push_back({a, b, fa, fab});
    if (job.plan.kind == domain::CampaignKind::fot && !job.prior_nodes.empty()) {  // the fits after a resume use every run: read off this loop
      loader->load(
          std::move(job), [this, &w](CampaignJob j) { post_main([this, &w, j = std::move(j)]() mutable { hand_over_loaded(w, std::move(j)); }); },
          [this, id](const std::string&) { post_main([this, id] { again(id); }); });
      return std::nullopt;
    }
    return job;
  }

  // A resumed campaign whose record is in: to its rig, unless it was ended while it was read.
  void hand_over_loaded(RigWorker& w, CampaignJob j) {
    try {
      const auto row = store.campaign(j.id);
      if (row && row->state == domain::CampaignState::queued) w.push_job(std::move(j));
    } catch (const std::exception& e) {
      spdlog::warn("campaign {}: not handed to its rig ({}); tried again", j.id, e.what());
      again(j.id);
    }
  }
  // Handed over again on a later pass (the database refused this one).
  void again(std::int64_t id) {
    dispatched.erase(id);
    redispatch = true;
  }

  // f on the main loop's next pass (dropped once the daemon stops accepting work).
  void post_main(std::function<void()> f) {
    {
      std::lock_guard lk(mu);
      if (!accepting) return;
      jobs.push_back(std::move(f));
    }
    cv.notify_all();
  }

  void store_io_stats() {
    for (auto& w : workers) {
      const auto h = w->rig->health();
      const json stats{
          {"reads", h.reads}, {"writes", h.writes}, {"errors", h.total_errors()}, {"reconnects", h.reconnects}, {"max_transaction_us", h.max_transaction_us}};
      const auto id = w->info.id;
      const std::string now = now_iso();
      writer->post([id, stats, now](db::Store& s) { s.add_io_stats(id, stats.dump(), now); });
    }
  }

  void run_jobs(double wait_s) {
    std::deque<std::function<void()>> todo;
    {
      std::unique_lock lk(mu);
      cv.wait_for(lk, std::chrono::duration<double>(wait_s), [this] { return !jobs.empty(); });
      todo.swap(jobs);
    }
    for (auto& j : todo) j();
  }

  // One pass over the queued campaigns (operators' commands arrive through the interface, never
  // the database). A busy or failing database is retried with back-off and reported once per
  // episode; it never ends run().
  void poll_database() {
    if (!redispatch) return;
    try {
      redispatch = false;
      dispatch();
      if (db_backoff_s > 0) spdlog::info("the database answers again");
      db_backoff_s = 0;
    } catch (const std::exception& e) {
      redispatch = true;
      if (db_backoff_s == 0) spdlog::error("the database refused the main loop ({}); retrying with back-off", e.what());
      db_backoff_s = std::min(2.0, std::max(0.1, 2 * db_backoff_s));
    }
  }
};

namespace {
// An HTTP HDF5 export's temporary file (web/src/routes_h5.cpp) is unlinked once open; a kill in
// between left it beside the database for good. Any left from an earlier run go at start-up.
void remove_leftover_exports(const std::string& db_path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path dir = fs::absolute(db_path, ec).parent_path();
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind("hystlab-export-", 0) != 0 || it->path().extension() != ".h5") continue;
    std::error_code rm;
    if (fs::remove(it->path(), rm)) spdlog::warn("removed a left-over export file: {}", it->path().string());
  }
}
}  // namespace

Daemon::Daemon(const DaemonConfig& config) : impl_(std::make_unique<Impl>(config)) {
  auto& d = *impl_;
  remove_leftover_exports(config.db_path);
  if (const int n = d.store.mark_interrupted(now_iso())) spdlog::warn("{} campaign(s) were left running: now interrupted", n);
  if (const int n = d.store.hold_queued(now_iso()))
    spdlog::warn("{} queued campaign(s) held after the restart: nothing moves until an operator releases them (resume)", n);
  for (const RigEntry& e : config.rigs) {
    auto w = std::make_unique<RigWorker>();
    w->entry = e;
    w->acquisition = config.acquisition;
    // A simulator shares the acquisition's CPU, just below it: its answers are then never queued
    // behind other threads. Not above real time: there its physics catch-up is real work, and at
    // SCHED_FIFO it starved the daemon (a campaign stalled at time scale 100 in an ASan build).
    w->entry.sim.cpu = resolve_cpu(config.acquisition.cpu);
    if (w->entry.sim.realtime_priority < 0)
      w->entry.sim.realtime_priority = w->entry.sim.cpu >= 0 && config.acquisition.priority > 1 && e.sim.time_scale <= 1 ? config.acquisition.priority - 1 : 0;
    try {
      w->build_rig(config.base_dir);
    } catch (const drivers::RigConfigError& err) {
      throw ConfigError(std::string("config: ") + err.what());
    }
    w->info.id = d.store.upsert_rig(e.name, e.simulated ? json{{"simulate", {{"time_scale", e.sim.time_scale}, {"rig", e.sim.rig}}}}.dump() : e.driver.dump(),
                                    now_iso());
    spdlog::info("rig '{}': {}", e.name, w->info.description);
    d.workers.push_back(std::move(w));
  }
  // The writer's thread starts off the acquisition's CPU and stays there: this kernel does not
  // preempt system calls (PREEMPT_NONE), so its writes and fsyncs on that CPU would hold back the
  // acquisition's wake-ups by milliseconds.
  const bool moved = avoid_cpu(resolve_cpu(config.acquisition.cpu));
  d.writer = std::make_unique<db::SampleWriter>(config.db_path);
  d.finisher = std::make_unique<Finisher>(*d.writer, [&d](FinishJob j) {
    struct Done {
      Impl& d;
      std::int64_t id;
      ~Done() {
        std::lock_guard lk(d.finishing_mu);
        d.finishing.erase(id);
      }
    } const done{d, j.campaign};
    return finish_campaign(std::move(j), *d.writer, now_iso);
  });
  d.loader = std::make_unique<ResumeLoader>(config.db_path);
  if (moved) (void)avoid_cpu(-1);
}

Daemon::~Daemon() {
  auto& d = *impl_;
  {
    std::lock_guard lk(d.mu);
    d.accepting = false;
  }
  d.loader.reset();
  for (auto& w : d.workers)
    if (w->thread.joinable()) w->thread.join();
  d.finisher.reset();  // what was handed over is finished
  d.writer->flush();
  for (auto& w : d.workers)
    if (w->sim) w->sim->stop();
}

void Daemon::run(const std::atomic<bool>& stop) {
  auto& d = *impl_;
  Offload offload;
  offload.finish = [&d](FinishJob j) {
    {
      std::lock_guard lk(d.finishing_mu);
      d.finishing.insert(j.campaign);
    }
    d.finisher->submit(std::move(j));
  };
  offload.background = [&d](std::function<void()> task) { d.finisher->post(std::move(task)); };
  for (auto& w : d.workers) w->thread = std::thread(rig_thread, std::ref(*w), std::ref(*d.writer), offload, std::cref(stop), d.config.base_dir);
  spdlog::info("hystlabd running: database {}", d.config.db_path);
  auto last_stats = std::chrono::steady_clock::now();
  while (!stop) {
    try {
      d.run_jobs(d.db_backoff_s > 0 ? d.db_backoff_s : 0.1);
      d.poll_database();
      if (std::chrono::steady_clock::now() - last_stats > std::chrono::seconds(10)) {
        last_stats = std::chrono::steady_clock::now();
        d.store_io_stats();
      }
    } catch (const std::exception& e) {  // never out of run(): the HTTP server and the rigs depend on it
      spdlog::error("main loop: {}", e.what());
    }
  }
  spdlog::info("hystlabd stopping: holding rigs, finishing the write batch");
  {
    std::lock_guard lk(d.mu);
    d.accepting = false;
  }
  try {
    d.run_jobs(0);  // what was accepted is carried out (or its caller times out)
  } catch (const std::exception& e) {
    spdlog::error("main loop: {}", e.what());
  }
  d.loader.reset();  // a load under way finishes; its job is dropped (no longer accepted): the campaign stays queued, held at the next start
  for (auto& w : d.workers) w->thread.join();  // each holds its rig and marks its campaign interrupted
  d.finisher.reset();
  d.writer->flush();
}

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

int run_daemon(const DaemonConfig& config, const std::atomic<bool>& stop) {
  Daemon d(config);
  d.run(stop);
  return 0;
}

}  // namespace hystlab::daemon
