#include "run_finish.hpp"

#include <nlohmann/json.hpp>

#include "hystlab/models/accuracy.hpp"
#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/lsq_fit.hpp"
#include "hystlab/models/preisach_model.hpp"

namespace hystlab::daemon {
namespace {
using nlohmann::json;

json accuracy_json(const models::AccuracyReport& r) {
  auto branch = [](const models::ErrorStats& s) {
    return json{{"samples", s.count}, {"rms_N", s.rms}, {"max_N", s.max_abs}, {"rms_norm", s.rms_norm}, {"max_norm", s.max_norm}};
  };
  json j{{"overall", branch(r.overall)}, {"ascending", branch(r.ascending)}, {"descending", branch(r.descending)},
         {"reference_range_N", r.reference_range}};
  if (r.energy_rel_error) j["loop_energy_rel_error"] = *r.energy_rel_error;
  return j;
}

models::AccuracyReport evaluate(const models::EverettTable& table, const std::vector<double>& x, const std::vector<double>& f) {
  models::PreisachModel m(table);
  std::vector<double> y(x.size());
  m.evaluate(x, y);
  return models::compare(x, f, y);
}
}  // namespace

void post_evaluation(db::SampleWriter& writer, std::int64_t campaign, const models::OnlineTableBuilder& builder,
                     const RunSeries& series, const std::string& now) {
  auto table = builder.table();
  const std::size_t known = builder.identified_nodes(), needed = builder.required_nodes();
  writer.post([campaign, table = std::move(table), x = series.x, f = series.f, known, needed, now](db::Store& s) {
    const json detail{{"nodes", known}, {"required", needed}, {"accuracy", accuracy_json(evaluate(table, x, f))}};
    s.add_event(campaign, "fit", detail.dump(), now);
  });
}

void finish_run(RunnerResult& r, std::int64_t campaign, const Plan& plan, const models::OnlineTableBuilder* builder,
                OnlineFot* fot, const RunSeries& series, RunnerContext& ctx) {
  if (fot) {
    fot->finish();  // the last descent ends here: evaluate it like the others
    if (fot->take_descent_completed() && builder) post_evaluation(ctx.writer, campaign, *builder, series, ctx.now_iso());
  }
  ctx.writer.flush();  // every sample, node and event of the run is on disk before the tables
  const std::string now = ctx.now_iso();
  if (r.state == "completed" && builder) {
    if (!builder->complete()) {
      r.state = "failed";
      r.reason = "the input ended with " + std::to_string(builder->identified_nodes()) + " of " +
                 std::to_string(builder->required_nodes()) + " FOT nodes measured";
    } else {
      const models::EverettTable table = builder->table();
      const models::DriftReport drift = models::drift_report(*builder);
      const json acc = accuracy_json(evaluate(table, series.x, series.f));
      models::TableProvenance prov{"campaign " + std::to_string(campaign), "fot", now, "run " + std::to_string(r.run_id),
                                   {{"accuracy", acc}, {"drift_max_spread_N", drift.max_spread}, {"drift_pooled_std_N", drift.pooled_std}}};
      r.table_id = ctx.store.add_table(campaign, r.run_id, "fot", plan.subdivisions, plan.lo_mm, plan.hi_mm, now, acc.dump(),
                                       models::table_to_json(table, prov).dump());
      const int n = std::min(plan.subdivisions, 24);
      try {
        const models::LsqFitResult fit = models::fit_preisach_lsq(series.x, series.f, models::Grid::make(plan.lo_mm, plan.hi_mm, n));
        const json lacc = accuracy_json(evaluate(fit.table, series.x, series.f));
        models::TableProvenance lp{"campaign " + std::to_string(campaign), "lsq", now, "run " + std::to_string(r.run_id),
                                   {{"accuracy", lacc}, {"lambda", fit.lambda}, {"rms_residual_N", fit.rms_residual}}};
        r.lsq_table_id = ctx.store.add_table(campaign, r.run_id, "lsq", n, plan.lo_mm, plan.hi_mm, now, lacc.dump(),
                                             models::table_to_json(fit.table, lp).dump());
      } catch (const std::invalid_argument& e) {
        ctx.store.add_event(campaign, "fit", json{{"lsq_skipped", e.what()}}.dump(), now);
      }
    }
  }
  ctx.store.end_run(r.run_id, r.state, now);
}

}  // namespace hystlab::daemon
