// The sine controller's quality through the isolator, where its outcome is deterministic: the
// campaign's own loop (run_campaign, the supervisor, the real writer and SQLite file) on the fake
// clock, against hystlab-sim's shaker physics in process (drivers/sim/in_process_rig.hpp). Time
// moves only when the loop sleeps, so no scheduler decides these figures: in real time against
// the simulator over Modbus the weakest window through the resonance read 0.896 on one loaded run
// and 0.91-0.94 on five others (issue 40), and here it reads the same on every run and machine.
// The real-time tests (test_shaker_campaign.cpp) keep what holds under load: completion, the
// steps and their changes, the link faults.
#include <doctest/doctest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "campaign_bench.hpp"
#include "hystlab/models/linear_spring.hpp"
#include "in_process_rig.hpp"
#include "shaker_checks.hpp"

using namespace hystlab;
using namespace hystlab::test;

namespace {
// A campaign on the simulated shaker of `hystlab-sim --rig shaker --linear 40` (13 kg on four
// 40 N/mm springs, the servo-driven table), in process on the fake clock, stored in its own file.
// Its parts are named by a structured binding: auto& [b, rig, plan, id, r] = run_ (a CAPTURE
// names a part through run_: clang 14 cannot capture a binding).
struct InProcessSweep {
  explicit InProcessSweep(const nlohmann::json& plan_json) : rig(make_shaker()), plan(domain::parse_plan(plan_json)), id(b.submit(plan.source)) {
    daemon::FakeClock clock;
    b.sup = std::make_unique<daemon::Supervisor>(*rig, domain::SupervisionSettings{}, true, [](const daemon::RigTransition&) {});
    daemon::RunnerContext ctx{*rig, *b.sup, *b.writer, clock};
    ctx.now_iso = [] { return std::string("2026-11-29T00:00:00Z"); };
    daemon::CampaignJob job;
    job.id = id;
    job.plan = plan;
    job.plan.limits = domain::check_plan_against(plan, domain::RigEnvelope{}, domain::SupervisionSettings{}, true);
    r = daemon::run_campaign(job, ctx);
    b.writer->flush();
  }
  static std::unique_ptr<sim::InProcessRig> make_shaker() {
    const models::LinearSpring spring(40);
    return std::make_unique<sim::InProcessRig>(sim::SimRig(std::make_unique<sim::ShakerSim>(spring, sim::ShakerParams{})), 1000);
  }
  Bench b;
  std::unique_ptr<sim::InProcessRig> rig;
  domain::Plan plan;
  std::int64_t id = 0;
  daemon::RunnerResult r;
};
}  // namespace

TEST_CASE("every frequency step of an isolation sweep keeps the base at its demand: never below 90 % across a change, the drive carried") {
  // Above the isolator's resonance (17.7 Hz), where it isolates: each step starts at the drive
  // learnt at its own frequency by the loop check (stop 31 started each at half of it).
  InProcessSweep run_({{"kind", "sine"},
                       {"frequencies_hz", {22, 26, 30, 36, 44}},
                       {"amplitude_mm", 0.005},
                       {"settle", {{"change", "1 %"}, {"consecutive", 2}}},
                       {"measured_cycles", 8},
                       {"sample_rate_hz", 1000}});
  auto& [b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  REQUIRE(end_of(r) == "completed");
  const auto pts = points_of(*b.store, id);
  REQUIRE(pts.size() == 5);
  for (const auto& p : pts) CHECK(std::fabs(p["control_error_pct"].get<double>()) <= 1.5);
  // From the first step's measurement to the last's: every window of one 22 Hz period.
  const double weakest = weakest_base_window(*b.store, r.run_id, pts.front()["t_s"].get<double>(), pts.back()["t_s"].get<double>(), 1 / 22.0, 0.005);
  MESSAGE("the weakest window of the base: " << weakest << " of its demand");
  CHECK(weakest >= 0.90);
  CHECK(weakest < 1.0);  // the windows were read: a real minimum, not the initial value
}

TEST_CASE(
    "through the resonance the base above 90 % of its demand across a change up (84 % down): a loop check learns every frequency; a burst "
    "moves the drive's phase across the peak and a glide goes elsewhere") {
  // Through the isolator's resonance (17.7 Hz, Q 25), where the mass's reaction on the table
  // changes its response 2.5 times between 17 and 18.5 Hz. Without the loop check each step started
  // at the drive learnt at the step before: the base read 22 % of its demand for a window after 17
  // -> 18.5 Hz. With it, each step starts at its own drive, and what was left was the mass's free
  // vibration, excited by the jump and beating with the table: 64 % (stop 34); the loop's
  // correction every cycle made it 81-84 % up (stop 36; a model of this rig put a down pass at
  // 42 % from 18.5 to 17 Hz). Now each change keeps the mass on its new step's motion
  // (sine_change.hpp): across the peak the drive's phase is moved by what the mass's phase against
  // it moves (a burst, 94° here), elsewhere the frequency glides, waiting for the base. Seen up:
  // every change's weakest window 95-97 %; down 93-96 %, but 91 % from 18.5 to 17 Hz.
  InProcessSweep run_({{"kind", "sine"},
                       {"frequencies_hz", {12, 15, 17, 18.5, 22}},
                       {"direction", "up-down"},
                       {"amplitude_mm", 0.005},
                       {"settle", {{"change", "1 %"}, {"consecutive", 2}}},
                       {"measured_cycles", 8},
                       {"sample_rate_hz", 1000}});
  auto& [b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  REQUIRE(end_of(r) == "completed");
  const auto pts = points_of(*b.store, id);
  REQUIRE(pts.size() == 10);
  // How each step was reached: a burst across the resonance (to 18.5 Hz up, to 17 Hz down), a
  // glide elsewhere, a pass's first (or a step taken again after a held link) from its start.
  int bursts = 0;
  for (const std::string& e : b.store->event_details(id, "sine_step")) {
    const auto j = nlohmann::json::parse(e);
    CAPTURE(e);
    const double f = j["frequency_hz"].get<double>();
    const bool across = (j["direction"] == "up" && f == 18.5) || (j["direction"] == "down" && f == 17);
    if (j["change"] == "start") continue;
    CHECK(j["change"] == (across ? "burst" : "glide"));
    if (j["change"] == "burst") {
      ++bursts;
      CHECK(std::fabs(j["shift_deg"].get<double>()) > 60);
      CHECK(std::fabs(j["shift_deg"].get<double>()) < 130);
    }
    if (j["change"] == "glide") CHECK(j["glide_cycles"].get<int>() >= 4);
  }
  CHECK(bursts == 2);
  for (const auto& p : pts) CHECK(std::fabs(p["control_error_pct"].get<double>()) <= 1.5);
  const auto checks = b.store->event_details(id, "pretest");
  REQUIRE(checks.size() == 1);
  const auto check = nlohmann::json::parse(checks[0]);
  CAPTURE(check.dump());
  CHECK(check["frequencies"] == 5);
  CHECK(check["level_mm"].get<double>() == doctest::Approx(0.00125));
  CHECK(check["response_max"].get<double>() > 1.5 * check["response_min"].get<double>());  // the table's response does change
  // Up, from the first step's measurement to the pass's last: every window of one 12 Hz period,
  // at least 90 % (the bound). On the fake clock 0.915, the same on every run (in real
  // time 0.896-0.94, the scheduler's share of it).
  const double weakest = weakest_base_window(*b.store, r.run_id, pts.front()["t_s"].get<double>(), pts[4]["t_s"].get<double>(), 1 / 12.0, 0.005);
  MESSAGE("the weakest window of the base, up: " << weakest << " of its demand");
  CHECK(weakest >= 0.90);
  CHECK(weakest < 1.0);  // the windows were read: a real minimum, not the initial value
  // Down (from the top step's measurement): the burst from 18.5 to 17 Hz is the weakest change.
  // On the fake clock the window that starts 7 ms before the 18.5 Hz point is measured, as the
  // burst begins, reads 0.847, below the 90 % up holds (windows aligned on that point read 0.929;
  // real-time runs 0.91-0.94, each aligned where its samples fell). Checked at 0.84, just under
  // the deterministic figure: a change to the burst shows here, and the jump it replaced read 42 %.
  const double weakest_down = weakest_base_window(*b.store, r.run_id, pts[5]["t_s"].get<double>(), pts.back()["t_s"].get<double>(), 1 / 12.0, 0.005);
  MESSAGE("the weakest window of the base, down: " << weakest_down << " of its demand");
  CHECK(weakest_down >= 0.84);
  CHECK(weakest_down < 1.0);
  for (std::size_t k = 1; k < pts.size(); ++k)  // which change it was
    MESSAGE("  " << pts[k - 1]["frequency_hz"].get<double>() << " -> " << pts[k]["frequency_hz"].get<double>()
                 << " Hz: " << weakest_base_window(*b.store, r.run_id, pts[k - 1]["t_s"].get<double>(), pts[k]["t_s"].get<double>(), 1 / 12.0, 0.005));
  // The check itself stays low: while it runs its base is never beyond half the demand.
  double t_first = NAN, check_peak = 0;
  b.store->for_each_shaker_sample(r.run_id, 0, 1 << 30, [&](const db::ShakerRow& row) {
    if (std::isnan(t_first)) t_first = row.t;
    if (row.t - t_first < check["seconds"].get<double>()) check_peak = std::max(check_peak, std::fabs(row.v.base_displacement_mm));
  });
  CAPTURE(check_peak);
  CHECK(check_peak > 0.0005);
  CHECK(check_peak < 0.0025);
}
