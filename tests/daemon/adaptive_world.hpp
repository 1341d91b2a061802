#pragma once
// An adaptive FOT campaign's world for the tests and bench_adaptive (issue 41): the simulated SMA
// load frame in process (Table 1 at the simulator's noise, 0.05 N) on a fake clock, a database and
// its writer, and what a campaign left: its end, its rig seconds (validation excluded), its design
// steps, its tables and its runs' samples. Every figure is then a function of the plan alone.
#include <atomic>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <utility>

#include "campaign_bench.hpp"
#include "hystlab/db/store.hpp"
#include "hystlab/models/adaptive_fot.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/models/table_score.hpp"
#include "in_process_rig.hpp"
#include "resume_loader.hpp"

namespace hystlab::test {
using nlohmann::json;
namespace {  // each program's own copy, as campaign_bench.hpp's Bench it holds

// What a campaign left: its end, its rig seconds (validation excluded), its tables, its design.
struct Outcome {
  daemon::RunnerResult result;
  double rig_s = 0;
  std::vector<domain::DesignEvent> design;
};

// 250 Hz: a quarter of the daemon's default samples, for the tests' time (under clang ASan, two
// at a time, the adaptive cases took 184 s at 500 Hz in stop 43's warm clean clone); the rows at
// 0.5 mm/s still have a sample every 2 µm of travel, 40 to a step of the finest grid.
constexpr double kTestRateHz = 250;

class World {
 public:
  explicit World(double rate_hz = kTestRateHz) : World(rate_hz, std::make_unique<models::SimplifiedSmaModel>(models::table1_parameters())) {}
  // Another specimen (an untrained one, a table) or frame (sharp corners) at the controller's rate.
  World(double rate_hz, std::unique_ptr<models::HysteresisModel> specimen, const sim::LoadFrameParams& frame = {})
      : rig(sim::SimRig(std::make_unique<sim::LoadFrameSim>(std::move(specimen), frame)), rate_hz) {
    b.sup = std::make_unique<daemon::Supervisor>(rig, domain::SupervisionSettings{}, false, [](const daemon::RigTransition&) {});
  }
  // Runs the plan (or resumes campaign `id` with what it measured); stop_after_design: once that
  // many design events were stored, the daemon stops (an interrupted campaign), or the operator's
  // `command` is given instead (once).
  Outcome run(const json& plan_json, std::int64_t resume = 0, std::size_t stop_after_design = 0, std::optional<daemon::Control> command = std::nullopt) {
    const domain::Plan plan = domain::parse_plan(plan_json);
    daemon::CampaignJob job;
    job.id = resume > 0 ? resume : b.submit(plan_json);
    job.plan = plan;
    job.plan.limits = domain::check_plan_against(plan, domain::RigEnvelope{}, domain::SupervisionSettings{}, false);
    if (resume > 0) {
      for (const auto& [a, be, fa, fab] : b.store->fot_nodes_of_campaign(resume)) job.prior_nodes.push_back({a, be, fa, fab});
      daemon::read_prior_record(*b.store, job);
    }
    std::atomic<bool> stopping{false};
    daemon::RunnerContext ctx{rig, *b.sup, *b.writer, clock};
    ctx.now_iso = [] { return std::string("2026-11-29T00:00:00Z"); };
    ctx.stop = &stopping;
    std::size_t designs = 0;
    ctx.on_state = [](const std::string&) {};
    ctx.next_control = [&]() -> std::optional<daemon::Control> {
      // The fake clock runs the campaign far faster than real time: the writer's ring (2 min at
      // 1 kHz) is emptied every 20 s of rig time so that every sample is stored.
      if (++polls % 10'000 == 0) b.writer->flush();
      if (stop_after_design > 0 && polls % 1000 == 0) {
        b.writer->flush();
        designs = b.store->event_details(job.id, "design").size();
        if (designs >= stop_after_design && !command) stopping = true;
        if (designs >= stop_after_design && command) return std::exchange(command, std::nullopt);
      }
      return std::nullopt;
    };
    Outcome o;
    o.result = daemon::run_campaign(job, ctx);
    b.writer->flush();
    id = job.id;
    if (const auto span = b.store->time_span(o.result.run_id)) o.rig_s = span->second - span->first;
    o.design = db::events_of<domain::DesignEvent>(*b.store, id);
    return o;
  }
  // A run's samples, as stored.
  daemon::Columns samples(std::int64_t run) {
    std::vector<float> x, f;
    (void)b.store->read_xy(run, 0, false, x, f);
    if (static_cast<std::int64_t>(x.size()) != b.store->sample_count(run)) throw std::runtime_error("a run's samples were not all stored");
    return {std::vector<double>(x.begin(), x.end()), std::vector<double>(f.begin(), f.end())};
  }
  // The campaign's fot table (lsq: its least-squares table).
  models::EverettTable table(const daemon::RunnerResult& r, bool lsq = false) {
    const std::optional<std::int64_t> which = lsq ? r.lsq_table_id : r.table_id;
    if (!which) throw std::runtime_error("the campaign has no table: " + r.reason);
    const auto doc = b.store->table_document(*which);
    if (!doc) throw std::runtime_error("the campaign's table is not stored");
    return models::table_from_json(*doc).table;
  }
  Bench b;
  daemon::FakeClock clock;
  sim::InProcessRig rig;
  std::int64_t id = 0;
  long polls = 0;
};

[[maybe_unused]] json plan_at_rate(int n, double rate_hz = kTestRateHz) {
  json p = fot_plan(n, 0.5);
  p["sample_rate_hz"] = rate_hz;
  return p;
}

[[maybe_unused]] json adaptive_plan(int coarse, double budget_s, double target = 0, double min_gain = 0.02, double rate_hz = kTestRateHz) {
  json p = plan_at_rate(coarse, rate_hz);
  p["design"] = {{"kind", "adaptive"}, {"budget_s", budget_s}, {"min_gain", min_gain}, {"finest_subdivisions", 48}};
  if (target > 0) p["design"]["target_rms_N"] = target;
  return p;
}

// The rows' tops an adaptive campaign drove, from its design events (the coarse rows first).
[[maybe_unused]] std::vector<double> tops(const Outcome& o) {
  std::vector<double> out = o.design.empty() ? std::vector<double>{} : o.design.front().nodes_mm;
  if (!out.empty()) out.erase(out.begin());  // δmin
  for (const domain::DesignEvent& e : o.design)
    if (e.stopped.empty()) out.push_back(e.alpha_mm);
  return out;
}

// The campaign's table after each design step (the rows measured then), scored on v.
[[maybe_unused]] std::vector<double> heldout_by_step(World& w, const Outcome& o, const json& plan, const daemon::Columns& v) {
  models::OnlineTableBuilder fine(domain::node_grid(domain::parse_plan(plan)));
  for (const auto& [al, be, fa, fab] : w.b.store->fot_nodes_of_campaign(w.id)) (void)fine.add({al, be, fa, fab});
  std::vector<double> out;
  for (const domain::DesignEvent& e : o.design) {
    std::vector<int> idx;
    for (double x : e.nodes_mm) idx.push_back(fine.grid().node_near(x, 1e-6));
    out.push_back(models::score_table(fine.restricted(idx).table(), v.x, v.f).overall.rms);
  }
  return out;
}

}  // namespace
}  // namespace hystlab::test
