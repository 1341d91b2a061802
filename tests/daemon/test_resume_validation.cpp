// A FOT campaign interrupted during its validation run, then resumed (issue 40): every node was
// measured before, so the resume drives no row, but it drives the validation input again, whole,
// and scores its tables on that run. Before, it ended completed at once, "finished without driving
// the rig", its tables scored on the interrupted run's part of the input or on none. On the fake
// clock against the simulated load frame in process (drivers/sim/in_process_rig.hpp), so the
// interruption falls in the validation run on every run.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "campaign_bench.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "in_process_rig.hpp"
#include "resume_loader.hpp"

using namespace hystlab;
using namespace hystlab::test;

TEST_CASE("a FOT campaign interrupted in its validation run resumes, drives the validation input again, whole, and scores its tables on it") {
  Bench b;
  daemon::FakeClock clock;
  sim::InProcessRig rig(
      sim::SimRig(std::make_unique<sim::LoadFrameSim>(std::make_unique<models::SimplifiedSmaModel>(models::table1_parameters()), sim::LoadFrameParams{})),
      1000);
  b.sup = std::make_unique<daemon::Supervisor>(rig, domain::SupervisionSettings{}, false, [](const daemon::RigTransition&) {});
  const nlohmann::json plan_json = fot_plan(4, 2.0);  // validation on (the default)
  const domain::Plan plan = domain::parse_plan(plan_json);
  REQUIRE(plan.validation.enabled);
  const std::int64_t id = b.submit(plan_json);
  daemon::CampaignJob job;
  job.id = id;
  job.plan = plan;
  job.plan.limits = domain::check_plan_against(plan, domain::RigEnvelope{}, domain::SupervisionSettings{}, false);

  // The first attempt: the daemon stops 2 s of rig time into the validation run.
  daemon::RigLive live;
  std::atomic<bool> stopping{false};
  int validation_ticks = 0;
  bool interrupt = true;
  daemon::RunnerContext ctx{rig, *b.sup, *b.writer, clock};
  ctx.now_iso = [] { return std::string("2026-11-29T00:00:00Z"); };
  ctx.live = &live;
  ctx.stop = &stopping;
  ctx.next_control = [&]() -> std::optional<daemon::Control> {
    if (live.phase.load() == static_cast<std::uint8_t>(daemon::CampaignPhase::validation) && ++validation_ticks == 2000 && interrupt) stopping = true;
    return std::nullopt;
  };
  const daemon::RunnerResult first = daemon::run_campaign(job, ctx);
  b.writer->flush();
  CAPTURE(first.reason);
  REQUIRE(end_of(first) == "interrupted");
  REQUIRE(validation_ticks >= 2000);  // it was in the validation run
  REQUIRE(first.validation_run_id > 0);
  const std::int64_t cut = b.store->sample_count(first.validation_run_id);
  CHECK(cut > 1000);

  // The resume, as the daemon makes it: every node measured so far, the earlier runs' record.
  daemon::CampaignJob again = job;
  for (const auto& [a, be, fa, fab] : b.store->fot_nodes_of_campaign(id)) again.prior_nodes.push_back({a, be, fa, fab});
  REQUIRE(again.prior_nodes.size() == 10);  // n = 4: every node measured (the table's 15 values less its diagonal)
  daemon::read_prior_record(*b.store, again);
  CHECK(again.prior_validation_run == first.validation_run_id);
  stopping = false, interrupt = false;
  validation_ticks = 0;
  const daemon::RunnerResult second = daemon::run_campaign(again, ctx);
  b.writer->flush();
  CAPTURE(second.reason);
  CHECK(end_of(second) == "completed");
  CHECK(second.reason.find("without driving") == std::string::npos);
  REQUIRE(second.validation_run_id > 0);
  CHECK(second.validation_run_id != first.validation_run_id);
  const std::int64_t whole = b.store->sample_count(second.validation_run_id);
  CAPTURE(cut);
  CAPTURE(whole);
  CHECK(whole > cut);
  CHECK(validation_ticks > 2000);  // the whole input, past where the first attempt was cut
  // The recommendation names the held-out run's error: the tables were scored on it.
  const auto recs = b.store->event_details(id, "recommendation");
  REQUIRE(!recs.empty());
  CHECK(recs.back().find("validation run") != std::string::npos);
}
