// The sine controller's quality through the isolator, where its outcome is deterministic: the
// campaign's own loop (run_campaign, the supervisor, the real writer and SQLite file) on the fake
// clock, against hystlab-sim's shaker physics in process (drivers/sim/in_process_rig.hpp). Time
// moves only when the loop sleeps, so no scheduler decides these figures: in real time against
// the simulator over Modbus the weakest window through the resonance read 0.896 on one loaded run
// and 0.91-0.94 on five others (issue 40), and here it reads the same on every run and machine.
// The real-time tests (test_shaker_campaign.cpp) keep what holds under load: completion, the
// steps and their changes, what is stored, the abort; the control figures are checked here.
#include <doctest/doctest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "campaign_bench.hpp"
#include "hystlab/daemon/isolator.hpp"
#include "hystlab/models/linear_spring.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/models/sweep_analysis.hpp"
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
  // The springs: `hystlab-sim --linear 40`'s by default, or any model (the simulator's default is
  // the simplified SMA model of Table 1); `isolator` predicts each step beside its measurement.
  explicit InProcessSweep(const nlohmann::json& plan_json, const models::HysteresisModel& spring = models::LinearSpring(40),
                          std::shared_ptr<const daemon::IsolatorModel> isolator = nullptr)
      : rig(make_shaker(spring)), plan(domain::parse_plan(plan_json)), id(b.submit(plan.source)) {
    daemon::FakeClock clock;
    b.sup = std::make_unique<daemon::Supervisor>(*rig, domain::SupervisionSettings{}, true, [](const daemon::RigTransition&) {});
    daemon::RunnerContext ctx{*rig, *b.sup, *b.writer, clock};
    ctx.now_iso = [] { return std::string("2026-11-29T00:00:00Z"); };
    daemon::CampaignJob job;
    job.id = id;
    job.plan = plan;
    job.plan.limits = domain::check_plan_against(plan, domain::RigEnvelope{}, domain::SupervisionSettings{}, true);
    job.isolator = std::move(isolator);
    r = daemon::run_campaign(job, ctx);
    b.writer->flush();
  }
  static std::unique_ptr<sim::InProcessRig> make_shaker(const models::HysteresisModel& spring) {
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

TEST_CASE("closed loop at the demand on SMA springs: each step within 1.5 %, the transmissibility and the isolator's prediction within 5 %") {
  // The simulator's default shaker: four springs of the simplified SMA model (Table 1), which at
  // 0.005 mm stay on their elastic line (40 N/mm). The campaign predicts each step with the same
  // isolator simulated (daemon::simulated_isolator) and stores it beside the measurement.
  const models::SimplifiedSmaModel sma(models::table1_parameters());
  InProcessSweep run_(sma_steps_plan(), sma, std::make_shared<const daemon::IsolatorModel>(daemon::simulated_isolator()));
  auto& [b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  REQUIRE(end_of(r) == "completed");
  const auto pts = points_of(*b.store, id);
  REQUIRE(pts.size() == 3);
  bool loop_had_work = false;
  for (const auto& p : pts) {
    CAPTURE(p.dump());
    const double f = p["frequency_hz"];
    // Held at the demand, not at the tolerance's edge (stop 31's loop stopped inside the
    // tolerance, approached from below, and measured 3.8 to 4.5 % low).
    CHECK(std::fabs(p["control_error_pct"].get<double>()) <= 1.5);
    CHECK(p["band"] == "within tolerance");
    loop_had_work = loop_had_work || std::fabs(p["drive_mm"].get<double>() / 0.005 - 1) > 0.05;
    const double ratio = p["ratio"].get<double>();
    CHECK(std::fabs(ratio / linear_ratio(f) - 1) < 0.05);
    CHECK(p["thd"].get<double>() < 0.02);  // a small motion: the springs stay on their elastic line
    CHECK(std::fabs(p["predicted_ratio"].get<double>() / ratio - 1) < 0.05);
  }
  CHECK(loop_had_work);  // the table's response is not 1: the drive differed from the demand
}

TEST_CASE("linear springs at 0.05 mm: the analytic isolator's transmissibility within 3 % and its phase within 0.05 rad") {
  // At 0.05 mm and 16 Hz the relative motion (0.22 mm) would pass the SMA springs' Ms; linear
  // springs keep the curve analytic there.
  InProcessSweep run_(linear_large_plan());
  auto& [b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  REQUIRE(end_of(r) == "completed");
  const auto pts = points_of(*b.store, id);
  REQUIRE(pts.size() == 3);
  for (const auto& p : pts) {
    CAPTURE(p.dump());
    const double f = p["frequency_hz"];
    CHECK(std::fabs(p["ratio"].get<double>() / linear_ratio(f) - 1) < 0.03);
    CHECK(std::fabs(std::remainder(p["phase_rad"].get<double>() - linear_phase(f), 2 * std::numbers::pi)) < 0.05);
    CHECK(p["thd"].get<double>() < 0.01);
  }
}

TEST_CASE("a resonance dwell tracks the phase: -90 degrees within 5 for its 300 cycles, at the frequency where the physics puts it") {
  // The linear isolator (f_n 17.7 Hz, Q 25). Started at 16 Hz (the phase there about -8 degrees),
  // the dwell moves the frequency until the mass lags its base by 90 degrees within 5, then holds
  // it there for 300 cycles.
  InProcessSweep run_(dwell_plan());
  auto& [b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  REQUIRE(end_of(r) == "completed");
  const auto dwell = b.store->event_details(id, "dwell");
  REQUIRE(dwell.size() == 1);
  const auto d = nlohmann::json::parse(dwell[0]);
  CAPTURE(d.dump());
  CHECK(d["locked"] == true);
  CHECK(d["cycles"].get<int>() >= 300);
  CHECK(d["frequency_hz"].get<double>() == doctest::Approx(linear_quadrature_hz()).epsilon(0.005));
  // Every window from where it was found (the phase within 5 degrees, the base within the 1 % of
  // control.converge) on: within 90 ± 5 degrees, the base at its demand.
  const auto pts = points_of(*b.store, id);
  REQUIRE(pts.size() >= 30);
  bool found = false;
  int held = 0;
  for (const auto& p : pts) {
    const double deg = p["phase_rad"].get<double>() * 180 / std::numbers::pi;
    CAPTURE(p.dump());
    found = found || (std::fabs(deg + 90) <= 5 && std::fabs(p["control_error_pct"].get<double>()) <= 1);
    if (!found) continue;
    CHECK(std::fabs(deg + 90) <= 5);
    CHECK(std::fabs(p["control_error_pct"].get<double>()) <= 1.5);
    ++held;
  }
  CHECK(held * 10 >= 300);
  CHECK(d["out_of_tolerance"] == 0);
  CHECK(d["phase_deg"].get<double>() == doctest::Approx(-90).epsilon(0.02));
}

TEST_CASE("amplitude levels ramped: each level measured within 1.5 % of its demand, the drive at most x2.2 a change") {
  InProcessSweep run_(ramp_plan());
  auto& [b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  REQUIRE(end_of(r) == "completed");
  double prev = 0, largest = 1;
  b.store->for_each_shaker_sample(r.run_id, 0, 1 << 30, [&](const db::ShakerRow& row) {
    const double dr = row.v.drive_amplitude_mm;
    if (prev > 0 && dr > 0 && dr != prev) largest = std::max(largest, std::max(dr / prev, prev / dr));
    prev = dr;
  });
  CHECK(largest <= 2.2);  // a ramp's x2 and the loop's correction on it
  CHECK(largest >= 1.5);  // the ramp's steps are there
  const auto pts = points_of(*b.store, id);
  REQUIRE(pts.size() == 3);
  for (const auto& p : pts) {
    CAPTURE(p.dump());
    CHECK(std::fabs(p["control_error_pct"].get<double>()) <= 1.5);
  }
}

TEST_CASE("a continuous sweep slow against the isolator: each window's ratio the steady one at its mean frequency, within 5 %") {
  InProcessSweep run_(slow_sweep_plan());
  auto& [b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  REQUIRE(end_of(r) == "completed");
  const auto pts = points_of(*b.store, id);
  REQUIRE(pts.size() >= 4);
  for (const auto& p : pts) {
    CAPTURE(p.dump());
    CHECK(std::fabs(p["ratio"].get<double>() / linear_ratio(p["frequency_hz"].get<double>()) - 1) < 0.05);
  }
}

TEST_CASE("resonance refinement: a Q of 25 measured within 10 %, at 17.7 Hz within 1 %, from four coarse steps either side of the peak") {
  // 13 kg on 4 linear springs of 40 N/mm, 58 N·s/m: f_n = 17.7 Hz, ζ = 0.020, Q = 1/(2ζ) = 25. The
  // plan's steps put 12 and 25 Hz either side of the peak, far outside its 0.7 Hz half-power band.
  InProcessSweep run_(refinement_plan());
  auto& [b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  REQUIRE(end_of(r) == "completed");
  const auto pts = points_of(*b.store, id);
  CHECK(pts.size() > 4);
  CHECK(pts.size() <= 4 + 30);
  std::vector<models::SweepPoint> sweep;
  for (const auto& p : pts) {
    CAPTURE(p.dump());
    sweep.push_back({p["frequency_hz"].get<double>(), p["ratio"].get<double>(), p["phase_rad"].get<double>()});
    CHECK(std::fabs(p["control_error_pct"].get<double>()) <= 1.5);  // every step's base at its demand
    CHECK(std::fabs(p["ratio"].get<double>() / linear_ratio(p["frequency_hz"].get<double>()) - 1) < 0.05);
  }
  const auto res = models::find_resonance(sweep);
  REQUIRE(res);
  CAPTURE(res->frequency_hz);
  CAPTURE(res->q);
  CHECK(res->resolved);
  CHECK(models::points_in_band(*res, sweep) >= 5);
  CHECK(res->q == doctest::Approx(25.0).epsilon(0.10));
  CHECK(res->frequency_hz == doctest::Approx(17.7).epsilon(0.01));
  CHECK(b.store->event_details(id, "resonance_unresolved").empty());
}
