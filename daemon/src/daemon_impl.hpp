#pragma once
// The daemon's state (Daemon::Impl): rigs, store, writer, finisher, the main loop's job queue,
// campaigns dispatched to their rigs' threads, and commands routed (daemon.cpp, daemon_requests.cpp).
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "finisher.hpp"
#include "hystlab/daemon/daemon.hpp"
#include "hystlab/domain/plan.hpp"
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

}  // namespace hystlab::daemon
