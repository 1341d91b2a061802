// A shaker's drive writes against a busy controller (in process: the fake controller, a fake
// clock, the real loop and writer): a late answer is a lost command, as the load frame's are: the
// table is held and the step taken again when the rig answers, a bounded number in a row, then
// the sweep fails with the reason and the table is left at zero drive.
#include <doctest/doctest.h>

#include "safety_world.hpp"

using namespace hystlab;
using namespace hystlab::test;

namespace {
nlohmann::json two_step_sweep() {  // two steps, about 1.5 s of rig time
  return {{"kind", "sine"},
          {"frequencies_hz", {20, 30}},
          {"amplitude_mm", 0.05},
          {"sample_rate_hz", 1000},
          {"measured_cycles", 4},
          {"settle", {{"change", "5 %"}, {"consecutive", 1}, {"min_cycles", 2}}},
          {"control", {{"tolerance", "5 %"}, {"window_cycles", 2}}}};
}
}  // namespace

TEST_CASE("sine: a drive write answered late is taken again, the sweep goes on") {
  SafetyWorld w(true, 1 << 16);
  w.idle(2);
  w.rig->late_drive_answers = 1;  // the sweep's first drive write: taken, answered late
  const auto job = w.job(two_step_sweep());
  const int holds_before = w.rig->log.zero_drives, disables_before = w.rig->log.disables;
  int disables_while_driving = 0;  // every period with a drive on the table: the disables so far
  const auto r = w.run(job, [&] {
    if (w.rig->drive() > 0) disables_while_driving = w.rig->log.disables - disables_before;
  });
  CAPTURE(r.reason);
  CHECK(r.end == daemon::CampaignEnd::completed);
  w.writer->flush();
  CHECK(w.store->transmissibility(job.id).size() == 2);  // both steps measured
  CHECK(w.rig->log.zero_drives > holds_before);          // held (zero drive) while it was unanswered
  CHECK(disables_while_driving == 0);                    // enable never dropped on the way (only at the end)
}

TEST_CASE("sine: a controller that keeps answering late fails the sweep after three lost writes, at zero drive") {
  SafetyWorld w(true, 1 << 16);
  w.idle(2);
  w.rig->late_drive_answers = 1000;
  const auto job = w.job(two_step_sweep());
  const auto r = w.run(job, {});
  CAPTURE(r.reason);
  CHECK(r.end == daemon::CampaignEnd::failed);
  CHECK(r.reason.find("shaker command refused") != std::string::npos);
  CHECK(r.reason.find("3 times in a row") != std::string::npos);
  CHECK(w.rig->drive() == 0.0);  // left without drive
  w.writer->flush();
  CHECK(w.store->transmissibility(job.id).empty());
}

TEST_CASE("a shaker's hold is zero drive with enable as the controller reported it: never a pulse of enable") {
  namespace st = protocols::status;
  FakeRig rig;
  rig.shaker = true;
  domain::SupervisionSettings settings;
  daemon::Supervisor sup(rig, settings, true, [](const daemon::RigTransition&) {});
  const daemon::StatusView ready{static_cast<std::uint16_t>(st::ready), 0, 0.0}, enabled{static_cast<std::uint16_t>(st::ready | st::enabled), 0, 0.0};
  // Start-up: the first answer re-asserts held and disabled, without enabling on the way (stop
  // 31 wrote the zero drive with enable on, then disabled: 1-2 ms of enable).
  CHECK_FALSE(sup.on_status(0.0, ready));
  CHECK(sup.state() == daemon::RigState::idle);
  CHECK(rig.log.enable_writes == 0);
  CHECK(rig.drive() == 0.0);
  // Armed (the arming writes enable once), then held: zero drive, still enabled.
  std::string reason;
  REQUIRE_FALSE(sup.begin_arming(0.1));
  CHECK(sup.arming_step(0.1, ready, reason) == daemon::Supervisor::Arming::pending);
  CHECK(rig.log.enable_writes == 1);
  CHECK(sup.arming_step(0.12, enabled, reason) == daemon::Supervisor::Arming::armed);
  (void)sup.on_status(0.13, enabled);
  sup.hold(0.14, "test: held");
  CHECK(rig.drive() == 0.0);
  CHECK(rig.enabled());  // as it was
  // The controller drops enable: held, and enable is not written back on.
  const int before = rig.log.enable_writes;
  CHECK(sup.on_status(0.15, ready));
  CHECK(rig.log.enable_writes == before);
  CHECK(rig.drive() == 0.0);
}
