// Sine campaigns on the simulated shaker (a real hystlab-sim over Modbus TCP): closed-loop base
// amplitude, the abort band, results per step, the prediction beside the measurement, and the
// shaker's samples in their own columns.
#include <doctest/doctest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <thread>

#include "../drivers/sim_process.hpp"
#include "campaign_bench.hpp"
#include "hystlab/daemon/isolator.hpp"
#include "hystlab/domain/signals.hpp"
#include "hystlab/models/sdof.hpp"
#include "hystlab/models/sweep_analysis.hpp"
#include "shaker_checks.hpp"

using namespace hystlab;
using namespace hystlab::test;

namespace {
// Read as hystlabd reads its simulated shaker: in blocks from the controller's sample window
// (polled, a starved host left a 110 Hz window with 29 of its 32 samples, four times in a row).
std::unique_ptr<drivers::Rig> shaker_rig(int port) {
  return drivers::make_rig({{"transport", "modbus-tcp"}, {"port", port}, {"rig", "shaker"}, {"block_reads", true}, {"stale_after_ms", 5000}});
}

// A figure that depends on how the scheduler treats the run, printed ("figure NAME VALUE") for the
// distributions its bound comes from. Measured in stop 42: 20 rounds on this 2-core machine, the
// clang ASan+UBSan tree as CI builds it, every real-time test case of this file and of
// test_sweep_api.cpp its own process, all ten at once, stress-ng --cpu 1 beside throughout (a
// heavier load than CI's): no failure, and each bound below is 3 times the worst deviation seen
// (at least 1 %, or 0.01 rad), the worst said beside it. The control's own quality is checked on
// the fake clock with the same plans (test_shaker_quality.cpp).
void figure(const std::string& name, double v) { MESSAGE("figure " << name << " " << v); }

// A campaign on its own hystlab-sim shaker (the simulator's arguments), read in blocks, stored in
// its own database, run in time_scale: the set-up every test here shares. Its parts are named
// by a structured binding: auto& [sim, b, rig, plan, id, r] = run_; a CAPTURE names a part through
// run_ (clang 14, the sanitized tree's compiler, cannot capture a binding).
struct ShakerSweep {
  ShakerSweep(std::vector<std::string> sim_args, const nlohmann::json& plan_json, double scale, std::shared_ptr<const daemon::IsolatorModel> isolator = nullptr)
      : sim(std::move(sim_args)), rig(shaker_rig(sim.modbus_port)), plan(domain::parse_plan(plan_json)), id(b.submit(plan.source)) {
    auto ctx = context(*rig, b, nullptr, scale, true);
    daemon::CampaignJob job;
    job.id = id;
    job.plan = plan;
    job.plan.limits = domain::check_plan_against(plan, domain::RigEnvelope{}, domain::SupervisionSettings{}, true);
    job.isolator = std::move(isolator);
    r = daemon::run_campaign(job, ctx);
  }
  SimProcess sim;
  Bench b;
  std::unique_ptr<drivers::Rig> rig;
  domain::Plan plan;
  std::int64_t id = 0;
  daemon::RunnerResult r;
};

std::int64_t rows_in(db::Store& store, const char* table, std::int64_t run) {
  db::Statement st(store.database(), std::string("SELECT count(*) FROM ") + table + " WHERE run_id = ?");
  st.bind(1, run);
  st.step();
  return st.column_int(0);
}
}  // namespace

TEST_CASE("sine campaign on the simulated shaker: the base held at the demand in closed loop, transmissibility and prediction per step") {
  // In slow motion (time scale 0.25): polled at 1 kHz, a starved 2-core VM leaves gaps of
  // 50-600 ms, and at 10 Hz in real time every window had over half of it in gaps.
  // The isolator rings at 17.7 Hz for 1/(ζω_n) = 0.45 s after each change: the settle criterion
  // waits until the mass amplitude stops changing (a fixed 10 cycles at 60 Hz measured a 16 %
  // high ratio with 9 % "distortion": the free vibration beating with the response).
  ShakerSweep run_({"--rig", "shaker", "--port", "0", "--time-scale", "0.25"}, sma_steps_plan(), 0.25,
                   std::make_shared<const daemon::IsolatorModel>(daemon::simulated_isolator()));
  auto& [sim, b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  REQUIRE(end_of(r) == "completed");
  const auto pts = points_of(*b.store, id);
  REQUIRE(pts.size() == 3);
  // The control figures are checked on the fake clock (test_shaker_quality.cpp: the same plan
  // and springs); here each step is measured and predicted, its figures printed.
  for (const auto& p : pts) {
    CAPTURE(p.dump());
    const double f = p["frequency_hz"], ratio = p["ratio"].get<double>();
    figure("sma_control_error_pct", std::fabs(p["control_error_pct"].get<double>()));
    figure("sma_ratio_over_linear", ratio / linear_ratio(f));
    figure("sma_prediction_over_ratio", p["predicted_ratio"].get<double>() / ratio);
    CHECK(std::fabs(p["control_error_pct"].get<double>()) < 2.7);             // worst 0.89 % of 60
    CHECK(std::fabs(ratio / linear_ratio(f) - 1) < 0.02);                     // worst 0.6 %
    CHECK(std::fabs(p["predicted_ratio"].get<double>() / ratio - 1) < 0.02);  // worst 0.6 %
  }
  // The shaker's samples are stored in their own columns, not the load frame's.
  CHECK(rows_in(*b.store, "shaker_samples", r.run_id) > 1000);
  CHECK(rows_in(*b.store, "samples", r.run_id) == 0);
  // The drive column: what the loop commanded while it drove (0 before the first step), below
  // the demand somewhere (the table gains above 1 here: the loop had work).
  double drive_min = 1;
  b.store->for_each_shaker_sample(r.run_id, 0, 1 << 30, [&](const db::ShakerRow& row) {
    if (row.v.drive_amplitude_mm > 0) drive_min = std::min(drive_min, row.v.drive_amplitude_mm);
  });
  figure("sma_drive_min_over_demand", drive_min / 0.005);
  CHECK(drive_min < 0.005);  // 0.125 of the demand in every run (the loop check's level)
}

TEST_CASE("sine campaign with linear springs: the transmissibility of the analytic linear isolator, at an amplitude that would transform SMA springs") {
  // hystlab-sim --linear 40: the same isolator (13 kg, 4 springs, 58 N·s/m) on linear springs of
  // the SMA springs' elastic stiffness. At 0.05 mm and 16 Hz the relative motion (0.22 mm) would
  // pass the SMA springs' Ms; linear springs keep the curve analytic there.
  ShakerSweep run_({"--rig", "shaker", "--port", "0", "--time-scale", "0.25", "--linear", "40"}, linear_large_plan(), 0.25);
  auto& [sim, b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  REQUIRE(end_of(r) == "completed");
  const auto pts = points_of(*b.store, id);
  REQUIRE(pts.size() == 3);
  for (const auto& p : pts) {
    CAPTURE(p.dump());
    const double f = p["frequency_hz"];
    const double phase_error = std::fabs(std::remainder(p["phase_rad"].get<double>() - linear_phase(f), 2 * std::numbers::pi));
    figure("linear_ratio_over_analytic", p["ratio"].get<double>() / linear_ratio(f));
    figure("linear_phase_error_rad", phase_error);
    CHECK(std::fabs(p["ratio"].get<double>() / linear_ratio(f) - 1) < 0.01);  // worst 0.08 % of 60
    CHECK(phase_error < 0.01);                                                // worst 0.0007 rad
  }
}

TEST_CASE("sine campaign: beyond the abort band the shaker is stopped, at zero drive, and the reason stored") {
  // 110 Hz is beyond the table's servo (60 Hz): the base follows a third of the drive, and the
  // plan allows the drive only 1.5 times the demand, so the base stays about 45 % short.
  ShakerSweep run_({"--rig", "shaker", "--port", "0", "--time-scale", "0.25"},
                   {{"kind", "sine"},
                    {"frequencies_hz", {110}},
                    {"amplitude_mm", 0.005},
                    {"sample_rate_hz", 1000},
                    {"control", {{"abort", "30 %"}, {"max_drive_ratio", 1.5}}}},
                   0.25);
  auto& [sim, b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  CHECK(end_of(r) == "aborted");
  CHECK(r.reason.find("control abort") != std::string::npos);
  CHECK(r.reason.find("abort band ±30 %") != std::string::npos);
  CHECK(b.store->event_details(id, "control_abort").size() == 1);
  // The shaker is left without drive: its base comes to rest.
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  double base = 0;
  for (int k = 0; k < 50; ++k) {
    drivers::ShakerSample s;
    if (!rig->read_shaker(0, s)) base = std::max(base, std::fabs(s.base_displacement_mm));
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  CHECK(base < 2e-4);
}

TEST_CASE("a resonance dwell tracks the phase: the mass held at -90 degrees against the base for its cycles, at the frequency where the physics puts it") {
  // hystlab-sim --linear 40: the linear isolator (f_n 17.7 Hz, Q 25). Started at 16 Hz (the
  // phase there about -8 degrees), the dwell moves the frequency until the mass lags its base by
  // 90 degrees within 5, then holds it there for 300 cycles.
  ShakerSweep run_({"--rig", "shaker", "--port", "0", "--linear", "40"}, dwell_plan(), 1.0);
  auto& [sim, b, rig, plan, id, r] = run_;
  CHECK(plan.sine.lowest_hz() == doctest::Approx(16 / 1.25));  // the envelope is checked over where tracking may go
  CAPTURE(run_.r.reason);
  REQUIRE(end_of(r) == "completed");
  const auto dwell = b.store->event_details(id, "dwell");
  REQUIRE(dwell.size() == 1);
  const auto d = nlohmann::json::parse(dwell[0]);
  CAPTURE(d.dump());
  CHECK(d["cycles"].get<int>() >= 300);
  CHECK(d["track"] == "phase");
  // Where it locked and how well it held are checked on the fake clock (test_shaker_quality.cpp).
  figure("dwell_locked", d["locked"] == true ? 1 : 0);
  figure("dwell_frequency_over_quadrature", d["frequency_hz"].get<double>() / linear_quadrature_hz());
  figure("dwell_out_of_tolerance", d["out_of_tolerance"].get<double>());
  CHECK(d["locked"] == true);  // locked in 20 of 20, at the quadrature frequency within 0.005 %, none out of tolerance
  CHECK(d["frequency_hz"].get<double>() == doctest::Approx(linear_quadrature_hz()).epsilon(0.01));
  CHECK(d["out_of_tolerance"] == 0);
  CHECK(points_of(*b.store, id).size() >= 30);  // a point every 10 cycles
}

TEST_CASE("amplitude levels ramped: from 0.005 to 0.05 mm and back the drive goes at most x2 a control window, never a jump of x10") {
  ShakerSweep run_({"--rig", "shaker", "--port", "0", "--linear", "40"}, ramp_plan(), 1.0);
  auto& [sim, b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  REQUIRE(end_of(r) == "completed");
  // The drive as commanded, sample by sample: each change at most ×2.2 (a ramp's ×2 and the
  // loop's correction on it), after the first step's start.
  double prev = 0, largest = 1;
  int changes = 0;
  b.store->for_each_shaker_sample(r.run_id, 0, 1 << 30, [&](const db::ShakerRow& row) {
    const double d = row.v.drive_amplitude_mm;
    if (prev > 0 && d > 0 && d != prev) largest = std::max(largest, std::max(d / prev, prev / d)), ++changes;
    prev = d;
  });
  CAPTURE(changes);
  figure("ramp_largest_change", largest);
  CHECK(largest <= 2.2);  // a ramp's x2 and the loop's correction on it: worst 2.017 of 20
  CHECK(largest >= 1.5);  // the ramp's steps are there
  const auto pts = points_of(*b.store, id);
  REQUIRE(pts.size() == 3);
  for (const auto& p : pts) {
    figure("ramp_control_error_pct", std::fabs(p["control_error_pct"].get<double>()));
    CHECK(std::fabs(p["control_error_pct"].get<double>()) < 2.5);  // each level at its demand: worst 0.85 % of 60
  }
  CHECK(pts[1]["amplitude_mm"] == 0.05);
}

TEST_CASE("a continuous sweep: the frequency moves every cycle at the plan's rate, each window a point at its mean frequency") {
  ShakerSweep run_({"--rig", "shaker", "--port", "0", "--time-scale", "0.5"}, slow_sweep_plan(), 0.5);
  auto& [sim, b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  REQUIRE(end_of(r) == "completed");
  const auto pts = points_of(*b.store, id);
  // 2 s from 8 to 11 Hz: about 19 cycles, 4 a point (the last window may cross the end).
  CHECK(pts.size() >= 4);
  CHECK(pts.size() <= domain::step_count(plan.sine) + 1);
  double last = 0;
  for (const auto& p : pts) {
    CAPTURE(p.dump());
    const double f = p["frequency_hz"];
    CHECK(f > last);  // upwards, window by window
    CHECK(f >= 8.0);
    CHECK(f <= 11.3);
    last = f;
    figure("sweep_ratio_over_linear", p["ratio"].get<double>() / linear_ratio(f));
    CHECK(std::fabs(p["ratio"].get<double>() / linear_ratio(f) - 1) < 0.01);  // worst 0.12 % of 100
  }
}

TEST_CASE("sine plans: sweeps, directions, amplitudes, settle and control, with errors that name the field") {
  const auto p = domain::parse_plan(nlohmann::json::parse(R"({"kind": "sine", "sweep": {"from_hz": 5, "to_hz": 60, "steps": 12},
      "direction": "up-down", "amplitudes_mm": [0.005, 0.05], "settle": {"change": "2 %"}, "control": {"tolerance": 4}})"));
  CHECK(p.sine.frequencies_hz.size() == 12);
  CHECK(p.sine.frequencies_hz.front() == doctest::Approx(5));
  CHECK(p.sine.frequencies_hz.back() == doctest::Approx(60));
  const auto passes = domain::sweep_passes(p.sine);
  REQUIRE(passes.size() == 4);
  CHECK((passes[0].up && !passes[1].up && passes[2].amplitude_mm == 0.05));
  CHECK(domain::pass_frequencies(p.sine, passes[1]).front() == doctest::Approx(60));
  CHECK(domain::step_count(p.sine) == 48);
  CHECK(p.sine.settle.until);
  CHECK(p.sine.control.tolerance_pct == 4);
  const auto c =
      domain::parse_plan(nlohmann::json::parse(R"({"kind": "sine", "sweep": {"from_hz": 5, "to_hz": 80, "rate_oct_min": 2}, "amplitude_mm": 0.01})"));
  CHECK(c.sine.continuous);
  CHECK(domain::nominal_duration_s(c.sine) > 120);  // 4 octaves at 2 oct/min
  auto bad = [](const char* text, const char* what) {
    CAPTURE(text);
    try {
      (void)domain::parse_plan(nlohmann::json::parse(text));
      FAIL("accepted");
    } catch (const domain::PlanError& e) {
      CHECK(std::string(e.what()).find(what) != std::string::npos);
    }
  };
  bad(R"({"kind": "sine", "sweep": {"from_hz": 5, "to_hz": 60}, "direction": "sideways", "amplitude_mm": 0.1})", "direction must be");
  bad(R"({"kind": "sine", "sweep": {"from_hz": 5, "to_hz": 60, "steps": 5, "rate_oct_min": 1}, "amplitude_mm": 0.1})", "sweep.steps is for a stepped sweep");
  bad(R"({"kind": "sine", "sweep": {"from_hz": 5, "to_hz": 60}, "amplitudes_mm": [0.1, -1]})", "amplitudes_mm[1] must be");
  bad(R"({"kind": "sine", "sweep": {"from_hz": 5, "to_hz": 60}, "amplitude_mm": 0.1, "control": {"warning": "20 %", "abort": "10 %"}})",
      "control.abort must be above control.warning");
  bad(R"({"kind": "sine", "sweep": {"from_hz": 5, "to_hz": 60}, "amplitude_mm": 0.1, "settle": {"change": "2 %"}, "settle_cycles": 4})",
      "settle and settle_cycles");
  bad(R"({"kind": "sine", "sweep": {"from_hz": 5, "to_hz": 600}, "amplitude_mm": 0.1})", "sweep.to_hz must stay below sample_rate_hz / 8");
  bad(R"({"kind": "sine", "frequencies_hz": [5, 5], "amplitude_mm": 0.1})", "must not repeat");
  bad(R"({"kind": "sine", "sweep": {"from_hz": 5, "to_hz": 80, "rate_oct_min": 2}, "amplitude_mm": 0.01, "resonance": true})",
      "resonance refines a stepped sweep's steps");
  bad(R"({"kind": "sine", "sweep": {"from_hz": 5, "to_hz": 60}, "amplitude_mm": 0.1, "resonance": {"half_power_points": 2}})",
      "resonance.half_power_points must be");
  bad(R"({"kind": "sine", "sweep": {"from_hz": 5, "to_hz": 60}, "amplitude_mm": 0.1, "resonance": {"points": 5}})", "resonance.points");
  bad(R"({"kind": "sine", "sweep": {"from_hz": 5, "to_hz": 60}, "dwell": {"frequency_hz": 17, "cycles": 10}, "amplitude_mm": 0.1})", "dwell or a sweep");
  bad(R"({"kind": "sine", "dwell": {"frequency_hz": 17}, "amplitude_mm": 0.1})", "dwell needs frequency_hz (where it starts) and cycles");
  bad(R"({"kind": "sine", "dwell": {"frequency_hz": 17, "cycles": 10, "track": "amplitude"}, "amplitude_mm": 0.1})", "dwell.track must be");
  bad(R"({"kind": "sine", "dwell": {"frequency_hz": 17, "cycles": 10}, "direction": "down", "amplitude_mm": 0.1})", "direction is for a sweep");
  bad(R"({"kind": "sine", "dwell": {"frequency_hz": 110, "cycles": 10, "track": "phase"}, "amplitude_mm": 0.1})",
      "dwell.frequency_hz must stay below sample_rate_hz / 8");  // 110 × 1.25 at 1 kHz
  const auto r = domain::parse_plan(nlohmann::json::parse(R"({"kind": "sine", "sweep": {"from_hz": 5, "to_hz": 60}, "amplitude_mm": 0.1, "resonance": true})"));
  CHECK(r.sine.resonance.refine);
  CHECK(r.sine.resonance.half_power_points == 5);
}

TEST_CASE("resonance refinement on the simulated shaker: a Q of 25 measured, not bounded, from four coarse steps (block reads, real time)") {
  // hystlab-sim --linear 40: 13 kg on 4 linear springs of 40 N/mm, 58 N·s/m: f_n = 17.7 Hz,
  // ζ = 0.020, Q = 1/(2ζ) = 25. The plan's steps put 12 and 25 Hz either side of the peak, far
  // outside its 0.7 Hz half-power band; the refinement finds it. In real time: read in blocks
  // from the controller's sample window, a starved host loses no sample.
  ShakerSweep run_({"--rig", "shaker", "--port", "0", "--linear", "40"}, refinement_plan(), 1.0);
  auto& [sim, b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  REQUIRE(end_of(r) == "completed");
  const auto pts = points_of(*b.store, id);
  CHECK(pts.size() > 4);
  CHECK(pts.size() <= 4 + 30);
  std::vector<models::SweepPoint> sweep;
  for (const auto& p : pts) {
    CAPTURE(p.dump());
    sweep.push_back({p["frequency_hz"].get<double>(), p["ratio"].get<double>(), p["phase_rad"].get<double>()});
    figure("refine_control_error_pct", std::fabs(p["control_error_pct"].get<double>()));
    figure("refine_ratio_over_linear", p["ratio"].get<double>() / linear_ratio(p["frequency_hz"].get<double>()));
    CHECK(std::fabs(p["control_error_pct"].get<double>()) < 3.0);                                            // worst 1.0 % of 362
    CHECK(std::fabs(p["ratio"].get<double>() / linear_ratio(p["frequency_hz"].get<double>()) - 1) < 0.025);  // worst 0.77 %
  }
  // The Q and the frequency it finds are checked on the fake clock (test_shaker_quality.cpp).
  const auto res = models::find_resonance(sweep);
  REQUIRE(res);
  CAPTURE(res->frequency_hz);
  CAPTURE(res->q);
  figure("refine_resolved", res->resolved ? 1 : 0);
  figure("refine_q_over_25", res->q / 25);
  figure("refine_frequency_over_17.7", res->frequency_hz / 17.7);
  CHECK(res->resolved);                                              // 20 of 20
  CHECK(res->q == doctest::Approx(25.0).epsilon(0.07));              // worst 2.3 % low
  CHECK(res->frequency_hz == doctest::Approx(17.7).epsilon(0.011));  // worst 0.34 % low
  CHECK(b.store->event_details(id, "resonance_unresolved").empty());
  // The samples kept: the controller's window (0.5 s deep) outlasts a starved host's pauses; a
  // longer freeze loses what it overwrote, counted (bench_shaker reports the figure, 0 targeted).
  CAPTURE(run_.r.missed_deadlines);
  CHECK(r.samples > 10000);
  CHECK(r.missed_deadlines * 2000 < r.samples);
}

TEST_CASE("a drive write answered 150 ms late at every frequency step (hystlab-sim late-step): taken again, the sweep completes at its demand") {
  // Answers are due within 50 ms: each step's first write is lost, and taken again.
  ShakerSweep run_({"--rig", "shaker", "--port", "0", "--time-scale", "0.5", "--linear", "40", "--fault", "late-step=150"},
                   {{"kind", "sine"},
                    {"frequencies_hz", {12, 25, 40}},
                    {"amplitude_mm", 0.005},
                    {"settle", {{"change", "1 %"}, {"consecutive", 2}}},
                    {"measured_cycles", 8},
                    {"sample_rate_hz", 1000}},
                   0.5);
  auto& [sim, b, rig, plan, id, r] = run_;
  CAPTURE(run_.r.reason);
  CHECK(end_of(r) == "completed");
  // Each new frequency's first write is lost: the loop check's 3 and the sweep's 3 at least.
  CHECK(b.sup->link_losses() >= 6);
  const auto pts = points_of(*b.store, id);
  REQUIRE(pts.size() == 3);
  for (const auto& p : pts) {
    figure("late_control_error_pct", std::fabs(p["control_error_pct"].get<double>()));
    figure("late_ratio_over_linear", p["ratio"].get<double>() / linear_ratio(p["frequency_hz"].get<double>()));
    CHECK(std::fabs(p["control_error_pct"].get<double>()) < 2.5);                                           // worst 0.82 % of 60
    CHECK(std::fabs(p["ratio"].get<double>() / linear_ratio(p["frequency_hz"].get<double>()) - 1) < 0.01);  // worst 0.3 %
  }
}
