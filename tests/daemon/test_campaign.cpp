// Campaigns end to end: the runner drives hystlab-sim over real sockets, stores into a real
// SQLite file through the writer thread, and fits the table online.
#include <doctest/doctest.h>
#include <sched.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <future>
#include <mutex>
#include <thread>

#include <random>
#include "../drivers/sim_process.hpp"
#include "campaign_bench.hpp"
#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/daemon/daemon.hpp"
#include "hystlab/daemon/online_fot.hpp"
#include "hystlab/daemon/realtime.hpp"
#include "hystlab/daemon/safety.hpp"
#include "hystlab/daemon/supervisor.hpp"
#include "hystlab/domain/envelope.hpp"
#include "hystlab/drivers/can_rig.hpp"
#include "hystlab/drivers/rig_factory.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/online_table_builder.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/protocols/signals.hpp"

namespace fs = std::filesystem;
using namespace hystlab;
using hystlab::test::SimProcess;
using namespace hystlab::test;

namespace {

// Runs a campaign while another thread sends the simulator faults: (wait in ms, command) in turn,
// counted from the campaign's "running" (arming takes a database round trip first, and a starved
// machine may take longer than a fixed wait).
daemon::RunnerResult run_with_faults(std::int64_t id, const domain::Plan& plan, daemon::RunnerContext& ctx, SimProcess& sim,
                                     const std::vector<std::pair<int, std::string>>& schedule) {
  std::atomic<bool> running{false}, over{false};
  auto before = ctx.on_state;
  ctx.on_state = [&](const std::string& s) {
    if (s == "running") running = true;
    if (before) before(s);
  };
  std::thread fault([&] {
    while (!running && !over) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    for (const auto& [wait_ms, command] : schedule) {
      std::this_thread::sleep_for(std::chrono::milliseconds(wait_ms));
      sim.control(command);
    }
  });
  const daemon::RunnerResult r = run(id, plan, ctx);
  over = true;
  fault.join();
  ctx.on_state = before;
  return r;
}
}  // namespace

// Over Modbus TCP to hystlab-sim in real time at 20 times: the table made online is the one the
// stored samples make offline, and everything is stored. At 0.5 mm/s a host stall's hole moves the
// frame at most 0.2 mm (the simulator catches up 20 ms at most), under half a step of 1 mm, so no
// node falls into one; at 200 times (until stop 44) one did, and rows were taken again. How close
// the table is to the specimen's is measured on the fake clock (test_campaign_quality.cpp).
TEST_CASE("fot campaign n = 4 over Modbus: the online table equals the offline one, every sample stored") {
  SimProcess sim({"--port", "0", "--time-scale", "20", "--noise", "0.05", "--corner-width", "0"});
  Bench b;
  auto rig = tcp_rig(sim.modbus_port);
  const auto plan = domain::parse_plan(fot_plan(4, 0.5));
  const auto id = b.submit(plan.source);
  auto ctx = context(*rig, b, nullptr, 20);
  const daemon::RunnerResult r = run(id, plan, ctx);
  b.writer->flush();
  CAPTURE(r.reason);
  REQUIRE(end_of(r) == "completed");
  CHECK(r.nodes >= 10);  // 10 nodes (and the nodes of a row taken again, were there a hole)
  REQUIRE(r.table_id);
  CHECK(r.lsq_table_id);
  CHECK(b.store->campaign(id)->state == domain::CampaignState::completed);
  // Offline: the same identification over the samples as stored.
  const models::Grid g = models::Grid::make(0, 4, 4);
  models::OnlineTableBuilder offline(g);
  daemon::OnlineFot fot(g, std::min(0.05 * g.step(), 0.02), [&](const models::FotNode& n, double) { (void)offline.add(n); });
  fot.set_spacing(0.001 * 20);  // as online: 1 ms polls at time scale 20
  b.store->for_each_sample(r.run_id, 0, 1LL << 40, [&](const db::SampleRow& s) { fot.feed(s.t, s.disp, s.force, true); });
  fot.finish();
  REQUIRE(offline.complete());
  db::Statement st(b.store->database(), "SELECT document FROM tables WHERE id = ?");
  st.bind(1, *r.table_id);
  REQUIRE(st.step());
  const models::EverettTable online = models::table_from_json(st.column_text(0)).table;
  const models::EverettTable off = offline.table();
  for (std::size_t k = 0; k < online.values().size(); ++k) CHECK(online.values()[k] == doctest::Approx(off.values()[k]).epsilon(1e-12));
  // Every sample stored: the campaign's run, then the validation run after the rows.
  REQUIRE(r.validation_run_id > 0);
  CHECK(b.store->sample_count(r.validation_run_id) > 0);
  CHECK(b.store->sample_count(r.run_id) + b.store->sample_count(r.validation_run_id) == static_cast<std::int64_t>(r.samples));
  // Every transition is stored with its reason.
  const auto ev = b.store->events(id);
  std::vector<std::string> states;
  for (const auto& e : ev)
    if (e.kind == "state") states.push_back(e.to_state);
  CHECK(states == std::vector<std::string>{"queued", "arming", "running", "completed"});
  std::size_t fits = 0;
  for (const auto& e : ev) fits += e.kind == "fit" ? 1U : 0U;
  CHECK(fits >= 4);  // one evaluation after each descent
}

TEST_CASE("safety: a force-limit trip aborts to the safe position, with the reason stored") {
  SimProcess sim({"--port", "0", "--time-scale", "200", "--noise", "0"});
  Bench b;
  auto rig = tcp_rig(sim.modbus_port);
  auto j = fot_plan(4, 0.2);
  j["limits"]["force_N"] = 60;
  const auto plan = domain::parse_plan(j);
  const auto id = b.submit(plan.source);
  auto ctx = context(*rig, b, nullptr, 200);
  const auto r = run(id, plan, ctx);
  b.writer->flush();
  CHECK(end_of(r) == "aborted");
  CHECK(r.reason.find("force") != std::string::npos);
  drivers::RigSample s;
  REQUIRE_FALSE(rig->read_sample(0, s));
  CHECK(std::fabs(s.displacement_mm - 0.0) < 0.05);  // back at the safe position
  CHECK(b.store->events(id).back().detail.find("safety trip") != std::string::npos);
}

TEST_CASE("operator: pause, a long pause's memory-aware resume, then abort") {
  SimProcess sim({"--port", "0", "--time-scale", "200", "--noise", "0"});
  Bench b;
  auto rig = tcp_rig(sim.modbus_port);
  const auto plan = domain::parse_plan(fot_plan(6, 0.1));
  const auto id = b.submit(plan.source);
  Controls c;
  auto ctx = context(*rig, b, &c, 200);
  std::vector<std::string> seen;
  std::mutex mu;
  std::condition_variable cv;
  ctx.on_state = [&](const std::string& s) {
    std::lock_guard lk(mu);
    seen.push_back(s);
    cv.notify_all();
  };
  // Each control once the loop has taken the one before (the states it reports), so that a stalled
  // loop cannot take a pause and its resume in one tick: the pause lasts 100 ms of wall time after
  // the loop took it, 20 rig-seconds at 200 times, longer than the 2 s threshold.
  auto after = [&](std::size_t states) {
    std::unique_lock lk(mu);
    return cv.wait_for(lk, std::chrono::seconds(30), [&] { return seen.size() >= states; });
  };
  std::thread operator_thread([&] {
    if (!after(2)) return;  // arming, running
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    c.push(daemon::Control::pause);
    if (!after(3)) return;  // paused
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    c.push(daemon::Control::resume);
    if (!after(4)) return;  // running
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    c.push(daemon::Control::abort);
  });
  const auto r = run(id, plan, ctx);
  operator_thread.join();
  b.writer->flush();
  CHECK(end_of(r) == "aborted");
  CHECK(seen == std::vector<std::string>{"arming", "running", "paused", "running", "aborted"});
  bool preamble = false;
  for (const auto& e : b.store->events(id)) preamble |= e.detail.find("wipe-out preamble") != std::string::npos;
  CHECK(preamble);
}

TEST_CASE("operator e-stop: passed to the rig at once, the campaign aborted") {
  SimProcess sim({"--port", "0", "--time-scale", "200", "--noise", "0"});
  Bench b;
  auto rig = tcp_rig(sim.modbus_port);
  const auto plan = domain::parse_plan(fot_plan(6, 0.1));
  const auto id = b.submit(plan.source);
  Controls c;
  auto ctx = context(*rig, b, &c, 200);
  std::atomic<bool> running{false};
  ctx.on_state = [&](const std::string& s) { running = running || s == "running"; };
  std::thread op([&] {  // 100 ms into the running campaign (of 1.4 s at least)
    for (int k = 0; k < 30000 && !running; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    c.push(daemon::Control::estop);
  });
  const auto r = run(id, plan, ctx);
  op.join();
  CHECK(end_of(r) == "aborted");
  CHECK(r.reason == "e-stop by the operator");
  drivers::RigSample s;
  REQUIRE_FALSE(rig->read_sample(0, s));
  CHECK((s.status_word & protocols::status::estop) != 0);
}

TEST_CASE("watchdog: a dropped connection holds and fails; a short drop recovers") {
  SimProcess sim({"--port", "0", "--time-scale", "200", "--noise", "0"});
  Bench b;
  auto rig = tcp_rig(sim.modbus_port);
  const auto plan = domain::parse_plan(fot_plan(4, 0.2));
  {
    const auto id = b.submit(plan.source);
    auto ctx = context(*rig, b, nullptr, 200);
    ctx.watchdog_fail_periods = 200;
    const auto r = run_with_faults(id, plan, ctx, sim, {{300, "fault drop"}});
    CAPTURE(r.reason);
    CHECK(end_of(r) == "failed");
    CHECK(r.reason.find("watchdog") != std::string::npos);
    sim.control("clear");
  }
  {
    const auto id = b.submit(plan.source);
    auto ctx = context(*rig, b, nullptr, 200);
    ctx.watchdog_fail_periods = 2000;
    const auto r = run_with_faults(id, plan, ctx, sim, {{300, "fault drop"}, {100, "clear"}});
    CAPTURE(r.reason);
    CHECK(end_of(r) == "completed");
    CHECK(rig->health().errors_of(drivers::RigError::connection_lost) >= 1);
  }
}

TEST_CASE("a stalled controller answers late: the campaign goes on, no false rate trip") {
  // As in a CI run: the simulator, starved of CPU at time scale 10, answered 44 ms late with the
  // position of that moment; timed by the request alone, that was 23 mm/s against a 20 mm/s limit.
  SimProcess sim({"--port", "0", "--time-scale", "10", "--noise", "0"});
  Bench b;
  auto rig = tcp_rig(sim.modbus_port);
  nlohmann::json source = fot_plan(4, 1.0);
  source["limits"]["rate_mm_s"] = 5;
  const auto plan = domain::parse_plan(source);
  const auto id = b.submit(plan.source);
  auto ctx = context(*rig, b, nullptr, 10);
  std::vector<std::pair<int, std::string>> stalls;  // eight stalls of 35 ms within the campaign's first 2 s
  for (int k = 0; k < 8; ++k) stalls.insert(stalls.end(), {{250, "fault stall 35"}, {5, "clear"}});
  const auto r = run_with_faults(id, plan, ctx, sim, stalls);
  CAPTURE(r.reason);
  CHECK(end_of(r) == "completed");
  CHECK(rig->health().max_transaction_us > 30'000);  // the stalls did happen
}

TEST_CASE("a full writer queue is counted and never blocks acquisition") {
  SimProcess sim({"--port", "0", "--time-scale", "200", "--noise", "0"});
  Bench b(8);  // far smaller than the 100 samples of one 100 ms batch window
  auto rig = tcp_rig(sim.modbus_port);
  const auto plan = domain::parse_plan(fot_plan(3, 0.4));
  const auto id = b.submit(plan.source);
  auto ctx = context(*rig, b, nullptr, 200);
  const auto r = run(id, plan, ctx);
  b.writer->flush();
  CAPTURE(r.reason);
  CHECK(end_of(r) == "completed");
  CHECK(r.dropped > 0);
  CHECK(b.writer->stats().dropped_full == r.dropped);
}

TEST_CASE("fot campaign over CAN (socketpair)") {
  int sv[2];
  REQUIRE(socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv) == 0);
  SimProcess sim({"--transport", "can", "--can-fd", "3", "--can-rate", "2000", "--time-scale", "20", "--noise", "0"}, sv[1]);
  close(sv[1]);
  drivers::CanRig rig(std::make_unique<drivers::FdCanChannel>(sv[0], "socketpair"), drivers::CanRigConfig{});
  Bench b;
  const auto plan = domain::parse_plan(fot_plan(4, 0.2));
  const auto id = b.submit(plan.source);
  auto ctx = context(rig, b, nullptr, 20);
  const auto r = run(id, plan, ctx);
  CAPTURE(r.reason);
  CAPTURE(r.late_wakeups);
  CAPTURE(r.missed_deadlines);
  CAPTURE(rig.health().lost_samples);
  CHECK(end_of(r) == "completed");  // every node identified (the run's table is complete)
  CHECK(r.nodes >= 10);             // 10 nodes, and those of rows taken again after a hole
}

TEST_CASE("safety envelope: limits on every sample; the rate over a window, not between two reads") {
  const domain::Limits l = envelope_limits(10);
  daemon::SafetyEnvelope env(l);
  // Steady 2 mm/s sampled with a jittery clock, the rig moving in 1 ms steps: reads 5 µs apart
  // may straddle one step (0.002 mm / 5 µs = 400 mm/s between them). Must not trip.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.9e-3, 0.9e-3);
  double t = 0;
  for (int k = 0; k < 2000; ++k) {  // 0 to 4 mm
    t += 1e-3 + (k % 7 == 0 ? jitter(rng) : 0.0);
    const double x = 2.0 * std::floor(t * 1000.0) / 1000.0;  // the rig's own 1 ms steps
    CAPTURE(k);
    REQUIRE_FALSE(env.check(x, 10.0, t));
  }
  // A real runaway (50 mm/s for 40 ms) trips on rate; a bad force or position at once.
  std::optional<std::string> trip;
  for (int k = 1; k <= 40 && !trip; ++k) trip = env.check(2 * t + 0.05 * k > 4.9 ? 4.9 : 2 * t + 0.05 * k, 10.0, t + k * 1e-3);
  REQUIRE(trip);
  CHECK(trip->find("rate") != std::string::npos);
  daemon::SafetyEnvelope env2(l);
  CHECK(env2.check(1.0, 150.0, 0.0)->find("force") != std::string::npos);
  CHECK(env2.check(6.0, 0.0, 0.001)->find("displacement") != std::string::npos);
}

TEST_CASE("safety envelope: a slow answer is no fast motion; a runaway with slow answers still trips") {
  const domain::Limits l = envelope_limits(5);
  // 1 mm/s, polled every 10 ms of rig time; one request waits 440 ms (a starved controller at
  // time scale 10, seen in CI) and comes back with the position of that moment.
  auto run = [&](bool bracketed) {
    daemon::SafetyEnvelope env(l);
    std::optional<std::string> trip;
    double asked = 0;
    for (int k = 0; k < 200 && !trip; ++k) {
      const double answered = asked + (k == 100 ? 0.44 : 0.0005);
      const double x = 1.0 * answered;
      trip = bracketed ? env.check(x, 10.0, asked, answered) : env.check(x, 10.0, asked);
      asked = answered + 0.0095;  // the next request goes out once this answer is in
    }
    return trip;
  };
  CHECK_FALSE(run(true));
  const auto unbracketed = run(false);  // timed by the request alone: 23 mm/s that never happened
  REQUIRE(unbracketed);
  CHECK(unbracketed->find("rate") != std::string::npos);
  // A real runaway at 50 mm/s, every answer 3 ms late: trips within a few windows.
  daemon::SafetyEnvelope env(l);
  std::optional<std::string> trip;
  double asked = 0;
  for (int k = 0; k < 100 && !trip; ++k, asked += 0.004) trip = env.check(50.0 * (asked + 0.003), 10.0, asked, asked + 0.003);
  REQUIRE(trip);
  CHECK(trip->find("rate") != std::string::npos);
  CHECK(asked < 0.1);
}

TEST_CASE("plans: an error names the field and the reason") {
  auto bad = [](nlohmann::json j, const char* needle) {
    CAPTURE(needle);
    CHECK_THROWS_WITH_AS((void)domain::parse_plan(j), doctest::Contains(needle), domain::PlanError);
  };
  bad({{"kind", "fot"}, {"subdivisions", 4}}, "range_mm is required");
  bad({{"kind", "fot"}, {"range_mm", {4, 0}}, {"subdivisions", 4}}, "range_mm must be [low, high]");
  bad({{"kind", "fot"}, {"range_mm", {0, 4}}, {"subdivisions", 0}}, "subdivisions must be an integer");
  bad({{"kind", "fot"}, {"range_mm", {0, 4}}, {"subdivisions", 4}, {"limits", {{"displacement_mm", {0, 3}}}}}, "range_mm must lie inside");
  bad({{"kind", "fot"}, {"range_mm", {0, 4}}, {"subdivisions", 4}, {"speed", 3}}, "speed is not a field");
  bad({{"kind", "sweep"}}, "kind must be");
  bad({{"kind", "waveform"}, {"points_mm", {0, "x"}}}, "points_mm[1] must be a number");
  bad({{"kind", "fot"}, {"range_mm", {0, 4}}, {"subdivisions", 4}, {"ramp_rate_mm_s", 30}, {"limits", {{"rate_mm_s", 10}}}},
      "ramp_rate_mm_s is above limits.rate_mm_s");
  // Without a rate of its own the plan parses; the rig's envelope refuses it, naming its maximum.
  const auto fast = domain::parse_plan({{"kind", "fot"}, {"range_mm", {0, 4}}, {"subdivisions", 4}, {"ramp_rate_mm_s", 30}});
  try {
    (void)domain::check_plan_against(fast, domain::RigEnvelope{}, domain::SupervisionSettings{}, false);
    FAIL("a ramp of 30 mm/s passed an envelope of 20 mm/s");
  } catch (const domain::PlanError& e) {
    CHECK(std::string(e.what()).find("ramp_rate_mm_s 30 exceeds the rig's maximum speed 20 mm/s") != std::string::npos);
  }
}

TEST_CASE("daemon config: acquisition settings and the simulator's priority, with errors that name the field") {
  using daemon::AcquisitionSettings;
  const auto c = daemon::parse_daemon_config(
      nlohmann::json::parse(R"({"acquisition": {"priority": 0, "cpu": "any"}, "rigs": [{"simulate": {"time_scale": 1, "realtime_priority": 5}}]})"));
  CHECK(c.acquisition.priority == 0);
  CHECK(c.acquisition.cpu == AcquisitionSettings::kAnyCpu);
  CHECK(c.rigs.at(0).sim.realtime_priority == 5);
  const auto d = daemon::parse_daemon_config(nlohmann::json(nullptr));
  CHECK(d.acquisition.priority == 20);
  CHECK(d.acquisition.cpu == AcquisitionSettings::kLastCpu);
  CHECK(d.rigs.at(0).sim.realtime_priority == -1);  // decided by the daemon from the acquisition's
  auto refused = [](const char* text, const char* what) {
    CAPTURE(text);
    try {
      (void)daemon::parse_daemon_config(nlohmann::json::parse(text));
      FAIL("accepted");
    } catch (const daemon::ConfigError& e) {
      CHECK(std::string(e.what()).find(what) != std::string::npos);
    }
  };
  refused(R"({"acquisition": {"priority": 99}})", "acquisition.priority must be");
  refused(R"({"acquisition": {"cpu": "first"}})", "acquisition.cpu must be");
  refused(R"({"acquisition": {"cpus": 1}})", "acquisition.cpus is not a known field");
  refused(R"({"acquisition": 3})", "acquisition must be an object");
  refused(R"({"rigs": [{"simulate": {"realtime_priority": -1}}]})", "rigs[0].simulate.realtime_priority must be");
  refused(R"({"rigs": [{"simulate": {"realtime_priority": 4294967306}}]})", "rigs[0].simulate.realtime_priority must be");
}

TEST_CASE("acquisition thread: pinned to the CPU it names, its priority as far as allowed") {
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  CHECK(daemon::resolve_cpu(daemon::AcquisitionSettings::kAnyCpu) == -1);
  CHECK(daemon::resolve_cpu(static_cast<int>(cpus)) == -1);  // not there
  CHECK(daemon::resolve_cpu(daemon::AcquisitionSettings::kLastCpu) == (cpus > 1 ? cpus - 1 : -1));
  std::string got;
  int cpu_seen = -2;
  std::thread t([&] {
    got = daemon::enter_acquisition_thread({0, daemon::AcquisitionSettings::kLastCpu});
    cpu_seen = sched_getcpu();
  });
  t.join();
  CAPTURE(got);
  CHECK(got.find("normal priority") == 0);
  if (cpus > 1) CHECK(cpu_seen == cpus - 1);
}
