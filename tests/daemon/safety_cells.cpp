// The safety matrix's cells: each state reached on the fake rig, one event injected there, the
// invariants and the event's own outcome asserted, the next campaign run after a reset.
#include "safety_cells.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "safety_cell.hpp"

namespace hystlab::test {

const char* to_string(State s) noexcept {
  constexpr const char* names[] = {"idle",
                                   "queued",
                                   "arming: checking ready",
                                   "arming: enable written",
                                   "preamble",
                                   "training",
                                   "ramping",
                                   "dwelling",
                                   "retake",
                                   "validation",
                                   "paused",
                                   "safing",
                                   "shaker loop check",
                                   "shaker control window",
                                   "shaker measuring window",
                                   "shaker ramp between levels",
                                   "shaker continuous sweep",
                                   "shaker resonance dwell",
                                   "shaker change between steps (a glide)",
                                   "finishing",
                                   "held after restart",
                                   "limit recovery (latched, on the way back)"};
  return names[static_cast<int>(s)];
}

const char* to_string(Event e) noexcept {
  constexpr const char* names[] = {"operator e-stop (rig)",
                                   "operator e-stop (campaign)",
                                   "abort",
                                   "pause",
                                   "resume",
                                   "reset",
                                   "controller e-stop bit",
                                   "controller fault",
                                   "limit trip",
                                   "not ready",
                                   "enable dropped",
                                   "link lost (1.5 s)",
                                   "stale counter (0.1 s)",
                                   "host heartbeat lost",
                                   "dead band",
                                   "exception in a strategy",
                                   "database busy (1 s)",
                                   "database failing (6 s)",
                                   "writer's ring full",
                                   "finisher failing"};
  return names[static_cast<int>(e)];
}

namespace {

bool loop_state(State s) {
  return s != State::idle && s != State::queued && s != State::finishing && s != State::held_after_restart && s != State::limit_recovery;
}

// Why a cell has nothing to act on, or an empty string when it applies.
std::string why_not(State s, Event e) {
  const bool no_campaign = s == State::idle || s == State::held_after_restart || s == State::limit_recovery;
  if (s == State::limit_recovery && campaign_event(e) && e != Event::dead_band && e != Event::strategy_exception && e != Event::db_busy &&
      e != Event::db_failing && e != Event::ring_full && e != Event::finisher_failing)
    return "no campaign runs: none arms while the frame is brought back (tests/web/test_limit_recovery.cpp)";
  if (e == Event::finisher_failing && no_campaign) return "no campaign is finished from this state";
  if ((e == Event::db_busy || e == Event::db_failing || e == Event::ring_full) && no_campaign)
    return "nothing is stored between campaigns: the idle reads never reach the database";
  if (e == Event::dead_band && s != State::limit_recovery && (no_campaign || s == State::queued || s == State::finishing || shaker_state(s)))
    return shaker_state(s) ? "a shaker has no positioning dead band (its base is held in closed loop)" : "no motion is commanded in this state";
  if (e == Event::strategy_exception && !loop_state(s)) return "no strategy runs in this state";
  if (campaign_event(e) && (s == State::idle || s == State::limit_recovery) && e != Event::finisher_failing && e != Event::dead_band)
    return "there is no campaign in this state";
  if (campaign_event(e) && (no_campaign || s == State::queued || s == State::finishing) && e != Event::finisher_failing &&
      !(s == State::limit_recovery && e == Event::dead_band) &&
      !(s == State::queued && (e == Event::db_busy || e == Event::db_failing || e == Event::ring_full)) && s != State::finishing)
    return "a campaign command here goes through the daemon's main loop (route): tests/daemon/test_daemon.cpp and tests/web";
  if (s == State::finishing && (e == Event::campaign_estop || e == Event::abort || e == Event::pause || e == Event::resume || e == Event::dead_band))
    return "the campaign no longer moves the rig: the daemon's main loop answers 409 while its tables are being built (daemon_impl.hpp, route)";
  return "";
}

std::string short_reason(const std::string& r) {
  std::string s = r.substr(0, std::min(r.find(" ("), r.find(';')));
  if (s.size() > 72) s = s.substr(0, 69) + "...";
  return s;
}
// A recovery's outcome in a table cell's words: "held and disabled: the rig reports fault 7".
std::string recovery_words(std::string r) {
  for (const std::string prefix : {"limit recovery stopped, the frame held and disabled: ", "limit recovery stopped: "})
    if (r.rfind(prefix, 0) == 0) r = (prefix.size() > 30 ? "held and disabled: " : "stopped: ") + r.substr(prefix.size());
  r = r.substr(0, r.find(" ("));
  return r.size() > 90 ? r.substr(0, 87) + "..." : r;
}
}  // namespace

void Cell::run_idle_state() {
  std::int64_t held_id = 0;
  std::optional<daemon::CampaignJob> job;
  if (state == State::held_after_restart) {
    held_id = world.store->create_campaign(world.rig_id, domain::CampaignKind::fot, fot_plan().dump(), "t");
    world.store->transition(held_id, domain::CampaignState::held, "held after the restart", "t");
  }
  if (state == State::queued || state == State::finishing) job = world.job(fot_plan());
  if (state == State::finishing) {  // the loop has handed its end to the finisher; the event comes now
    const auto r = world.run(*job, [this] { ++ticks; });
    if (r.end != CampaignEnd::completed) fail("the finishing scenario's campaign did not complete: " + r.reason);
  }
  inject(event);
  for (int k = 0; k < 6; ++k) {
    world.idle(1);
    if (acted_tick < 0 && Writes(rig()).safe_write_since(*at_event, rig())) acted_tick = event_tick + k + 1;
    if (sup().latched() && std::isnan(latched_x)) latched_x = rig().position();
  }
  daemon::RunnerResult r;
  bool ran = false;
  if (state == State::queued) {
    r = world.run(*job, [this] { tick(); });
    acted_after_loop();
    world.idle(1);
    if (auto f = world.finish(event == Event::finisher_failing)) r = *f;
    ran = true;
  }
  if (state == State::finishing) {
    if (auto f = world.finish(event == Event::finisher_failing)) r = *f;
    ran = true;
  }
  world.idle(3);
  if (held_id && world.store->campaign(held_id)->state != domain::CampaignState::held) fail("the held campaign left 'held' without an operator");
  check_after(r, ran, job ? job->id : 0);
}

// A frame that left its stroke (placed at 12.3 mm, the controller's stroke 12 mm), latched, and
// on its way back at the safe rate (to 9.5 mm, inside the configured ±10 mm) when the event comes.
// Watched until the recovery has ended: nothing may move once latched or held.
void Cell::run_recovery_state() {
  rig().stroke_mm = 12.0;
  rig().place(12.3);
  world.idle(2);
  if (!sup().latched()) fail("the frame beyond its stroke did not latch");
  auto recovering = world.w.push_rig_command(RigCommand::recover);
  for (int k = 0; k < 40 && !(sup().recovering() && rig().enabled() && rig().position() < 12.2); ++k) world.idle(1);
  if (!sup().recovering() || rig().position() >= 12.2) return fail("the recovery never started moving the frame");
  event_tick = ticks;
  inject(event);
  double stopped_x = NAN;
  for (int k = 0; k < 1200 && (sup().recovering() || k < 40); ++k) {  // 2 s at least: a lost link's 1.5 s is over
    world.idle(1);
    ++ticks;
    if (acted_tick < 0 && Writes(rig()).safe_write_since(*at_event, rig())) acted_tick = ticks;
    // Stopped once the rig has taken it (held, disabled or latched): a rig that cannot be reached
    // goes on until its own host watchdog stops it (0.5 s here), as a real controller does.
    const bool halted = sup().latched() && !sup().recovering() && (rig().held() || !rig().enabled() || rig().latched());
    if (halted && std::isnan(stopped_x)) stopped_x = rig().position();
    if (halted && std::fabs(rig().position() - stopped_x) > 0.02) moved_while_latched = true;
  }
  if (sup().recovering()) fail("the recovery never ended");
  if (event == Event::reset) {  // refused while the frame comes back: only a stop interrupts a recovery
    if (!answer || answer->wait_for(std::chrono::seconds(0)) != std::future_status::ready)
      fail("the reset was never answered");
    else if (const CommandOutcome o = answer->get(); o.result != CommandOutcome::Result::conflict)
      fail("a reset during the recovery was answered " + o.reason);
    else
      reset_refused = true;
  }
  if (event != Event::reset && event != Event::stale_counter && recovering.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
    const CommandOutcome o = recovering.get();
    if (o.result == CommandOutcome::Result::done) fail("the recovery was answered done through the event: " + o.reason);
  }
  check_after({}, false, 0);
}

void Cell::run() {
  world.idle(4);  // connected: the first answer re-asserts held and disabled
  if (state == State::limit_recovery) return run_recovery_state();
  if (!loop_state(state)) return run_idle_state();
  const auto job = world.job(shaker_state(state) ? shaker_plan(state) : fot_plan());
  const auto r = world.run(job, [this] { tick(); });
  acted_after_loop();
  if (!injected) fail("the state was never reached (the scenario is broken)");
  world.idle(3);  // the rig's thread is idle again: a confirmation read there answers the e-stop
  daemon::RunnerResult fin = r;
  if (auto f = world.finish(event == Event::finisher_failing)) fin = *f;
  check_after(fin, true, job.id);
}

void Cell::check_after(const daemon::RunnerResult& r, bool ran, std::int64_t id) {
  lock.join();
  world.writer->flush();
  const FakeRig& fr = rig();
  // A pause has nothing to stop while paused, on the way to the safe position (it means nothing
  // there) or while arming (the rig is held until armed; the campaign is paused once armed);
  // not ready and a dropped enable need nothing written to a rig that is not armed.
  const bool armed_state = loop_state(state) && state != State::arming_ready && state != State::arming_enable;
  bool stop = stop_event(event);
  if (event == Event::pause && (!armed_state || state == State::paused || state == State::safing)) stop = false;
  if ((event == Event::not_ready || event == Event::enable_dropped) && !armed_state && state != State::limit_recovery) stop = false;
  if (event == Event::abort && state == State::safing) stop = false;  // already on its way to the safe position
  // Invariants, every cell.
  if (moved_while_latched) fail("the rig moved while latched");
  if (fr.log.setpoints_while_latched || fr.log.enables_while_latched || fr.log.drives_while_latched)
    fail("the host commanded a latched rig (setpoints " + std::to_string(fr.log.setpoints_while_latched) + ", enables " +
         std::to_string(fr.log.enables_while_latched) + ", drives " + std::to_string(fr.log.drives_while_latched) + ")");
  if (fr.enabled() && !fr.latched()) fail("the rig was left enabled after the campaign");
  if (ran) {
    if (r.end == CampaignEnd::none) fail("the campaign did not end");
    const auto row = world.store->campaign(id);
    if (!row || !domain::is_final(row->state))
      fail("the stored campaign is not in a terminal state: " + std::string(row ? domain::to_string(row->state) : "none"));
    if (r.end != CampaignEnd::completed && r.reason.empty()) fail("the campaign ended without a reason");
  }
  // The event's own outcome.
  const int bound = acted_tick < 0 ? -1 : acted_tick - event_tick;
  if (stop && (bound < 0 || bound > 2)) fail("the first safe write came " + std::to_string(bound) + " periods after the event (bound: 2)");
  if (event == Event::rig_estop || event == Event::campaign_estop) {
    if (sup().state() != RigState::estopped || !fr.latched()) fail("not latched in e-stop after the operator's e-stop");
    if (loop_state(state) && r.end != CampaignEnd::aborted && r.end != CampaignEnd::failed) fail("the campaign was not ended by the e-stop");
  }
  if (event == Event::rig_estop && answer) {
    if (answer->wait_for(std::chrono::seconds(0)) != std::future_status::ready)
      fail("the e-stop was never answered");
    else if (const CommandOutcome o = answer->get(); o.result != CommandOutcome::Result::done || !o.confirmed || !o.latched)
      fail("the e-stop was answered " + std::string(control::to_string(o.result)) + ": " + o.reason);
  }
  if ((event == Event::ctl_estop || event == Event::ctl_fault || event == Event::limit_trip) && !sup().latched())
    fail("the controller's latch was not latched");
  if (event == Event::pause && loop_state(state) && moved_while_paused) fail("the rig moved while paused");
  if (event == Event::pause && (state == State::arming_ready || state == State::arming_enable) && !saw_paused)
    fail("a pause while arming was not applied once armed");
  if (event == Event::strategy_exception && (r.end != CampaignEnd::failed || r.reason.find("acquisition thread") == std::string::npos))
    fail("an exception did not fail the campaign with its reason: " + r.reason);
  if (event == Event::finisher_failing && ran && r.reason.find("finishing failed") == std::string::npos) fail("a failing finisher did not fail the campaign");
  if (event == Event::ring_full && ran && loop_state(state) && r.dropped == 0) fail("the writer's ring never filled (the cell tested nothing)");
  // The bound is shown for the events whose first act is a write: the stops, and the watchdogs'
  // holds (a stale counter, a dead band's missed target, the controller's own heartbeat stop).
  const bool shown = stop || (event == Event::stale_counter && state != State::limit_recovery) || event == Event::dead_band || event == Event::heartbeat_lost;
  describe(r, ran, shown ? bound : -1);
  recover_and_run_next();
}

void Cell::describe(const daemon::RunnerResult& r, bool ran, int bound) {
  std::string o = ran ? std::string(daemon::to_string(r.end)) : "no campaign";
  if (ran && !r.reason.empty()) o += ": " + short_reason(r.reason);
  if (state == State::limit_recovery)
    o = std::string(reset_refused ? "the reset refused (409), " : "") + "recovery: " + recovery_words(sup().recovery_result());
  if (closed_tick >= 0) o += " (went on; ended by an abort " + std::to_string(closing_ticks()) + " periods later)";
  // (where the loop runs when the event comes, the ring is asserted to have filled; elsewhere how
  // much of the run meets the lock is the host's timing, and the text must not depend on it)
  if (event == Event::ring_full && loop_state(state)) o += "; samples dropped at the full ring, counted in the run's quality";
  o += " · rig " + std::string(daemon::to_string(sup().state()));
  out.outcome = o;
  if (std::getenv("HYSTLAB_SAFETY_ONLY")) out.outcome += " [" + r.reason + "]";  // the whole reason when looking at a few cells
  const bool loop = loop_state(state);
  if (bound >= 0)
    out.bound = std::to_string(bound) + (loop ? " period" + std::string(bound == 1 ? "" : "s") : " idle tick" + std::string(bound == 1 ? "" : "s"));
  else if (event == Event::link_lost)
    out.bound = "the hold re-asserted at the link's first answer";
  else
    out.bound = "-";
}

// After a reset, the next campaign must run: the event's causes cleared, the latch reset, the run completed.
void Cell::recover_and_run_next() {
  rig().plan.clear();
  rig().deadband_mm = 0;
  rig().clear_cause();
  world.idle(2);  // the rig answers again: what it latched meanwhile (fault 4 after a lost link) is seen first
  const bool beyond = state == State::limit_recovery && (rig().position() > 10.0 || (sup().last_status().status & st::limit_tripped));
  if (sup().latched() && !(beyond && (sup().last_status().status & st::limit_tripped))) {
    auto reset = world.w.push_rig_command(RigCommand::reset);
    world.idle(4);
    if (reset.wait_for(std::chrono::seconds(0)) != std::future_status::ready || reset.get().result != CommandOutcome::Result::done)
      fail("the operator's reset did not clear the latch");
  }
  if (beyond) {  // the frame back into its stroke first, as the operator would
    auto back = world.w.push_rig_command(RigCommand::recover);
    for (int k = 0; k < 200 && back.wait_for(std::chrono::seconds(0)) != std::future_status::ready; ++k) world.idle(1);
    if (back.wait_for(std::chrono::seconds(0)) != std::future_status::ready || back.get().result != CommandOutcome::Result::done)
      fail("the frame was not brought back into its stroke after the event");
  }
  world.idle(2);
  auto plan = next_plan(rig().shaker);
  if (state == State::limit_recovery) plan["limits"]["displacement_mm"] = {-0.5, 10};  // from 9.5 mm
  const auto next = world.job(plan);
  const auto r = world.run(next, {});
  world.idle(1);
  (void)world.finish(false);
  if (r.end != CampaignEnd::completed) fail("the next campaign after the reset did not complete: " + std::string(daemon::to_string(r.end)) + ": " + r.reason);
}

CellResult run_cell(State s, Event e) {
  Cell c(s, e);
  c.out.why_not = why_not(s, e);
  if (!c.out.why_not.empty()) {
    c.out.applies = false;
    return c.out;
  }
  try {
    c.run();
  } catch (const std::exception& ex) {
    c.fail(std::string("an exception escaped the cell: ") + ex.what());
  }
  return c.out;
}

CellResult run_schedule(bool shaker, const std::vector<std::pair<double, Event>>& schedule) {
  Cell c(shaker ? State::shaker_measure : State::ramping, Event::resume);  // resume: no stop until one is scheduled
  c.schedule = schedule;
  std::sort(c.schedule.begin(), c.schedule.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  c.schedule_mode = true;
  c.out.state = shaker ? "a whole sweep" : "a whole FOT campaign";
  c.out.event = "a seeded schedule";
  try {
    c.world.idle(4);
    const auto job = c.world.job(shaker ? sine_plan() : fot_plan());
    const auto r = c.world.run(job, [&c] { c.tick(); });
    c.acted_after_loop();
    c.world.idle(3);
    daemon::RunnerResult fin = r;
    if (auto f = c.world.finish(false)) fin = *f;
    c.check_after(fin, true, job.id);
  } catch (const std::exception& ex) {
    c.fail(std::string("an exception escaped: ") + ex.what());
  }
  return c.out;
}

std::string matrix_markdown(const std::vector<CellResult>& cells) {
  std::ostringstream o;
  std::string state;
  for (const CellResult& c : cells) {
    if (c.state != state) {
      state = c.state;
      o << "\n#### " << state << "\n\n| event | outcome | first safe write |\n|---|---|---|\n";
    }
    if (!c.applies)
      o << "| " << c.event << " | does not apply: " << c.why_not << " | - |\n";
    else
      o << "| " << c.event << " | " << c.outcome << " | " << c.bound << " |\n";
  }
  return o.str();
}

}  // namespace hystlab::test
