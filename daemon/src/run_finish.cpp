#include "run_finish.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <vector>

#include "hystlab/models/accuracy.hpp"
#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/fit_report.hpp"
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

namespace {
// The fot tables of a finished campaign: the calibrated table from every node, with its accuracy
// on every sample of every run, drift and provenance; and the constrained least-squares table.
std::vector<db::Store::TableRecord> fot_tables(FinishJob& j, const std::string& now, std::string& note) {
  std::vector<db::Store::TableRecord> out;
  const Plan& plan = j.plan;
  const models::EverettTable table = j.builder->table();
  const models::DriftReport drift = models::drift_report(*j.builder);
  const json acc = accuracy_json(evaluate(table, j.series.x, j.series.f));
  const std::string source = "campaign " + std::to_string(j.campaign), run = "run " + std::to_string(j.result.run_id);
  models::TableProvenance prov{source, "fot", now, run,
                               {{"accuracy", acc}, {"drift_max_spread_N", drift.max_spread}, {"drift_pooled_std_N", drift.pooled_std}}};
  out.push_back({"fot", plan.subdivisions, plan.lo_mm, plan.hi_mm, acc.dump(), models::table_to_json(table, prov).dump()});
  // The least-squares table, its prior (signed or monotone masses) decided by its error on
  // held-out blocks of the record (the CLI's `fit`, same code and figures). At most n = 24, as
  // before: the campaign's end (and a shutdown) waits for it, the fit cannot be cancelled yet, and
  // its cross-validation costs O(samples) per solver step (bench_fit: n = 48 on 10^5 samples 30 s).
  const int n = std::min(plan.subdivisions, 24);
  try {
    const models::PreisachFitResult fit =
        models::fit_preisach(j.series.x, j.series.f, models::Grid::make(plan.lo_mm, plan.hi_mm, n));
    const json lacc = accuracy_json(evaluate(fit.chosen.table, j.series.x, j.series.f));
    json extra = models::fit_provenance(fit);
    extra["accuracy"] = lacc;
    models::TableProvenance lp{source, "lsq", now, run, std::move(extra)};
    out.push_back({"lsq", n, plan.lo_mm, plan.hi_mm, lacc.dump(),
                   models::table_to_json(fit.chosen.table, lp).dump()});
  } catch (const std::exception& e) {  // optional: its failure never costs the campaign its fot table
    note = std::string("; least-squares table skipped: ") + e.what();
  }
  return out;
}
}  // namespace

RunnerResult finish_campaign(FinishJob j, db::SampleWriter& writer, const std::function<std::string()>& now_iso) {
  RunnerResult r = j.result;
  const std::string now = now_iso();
  std::vector<db::Store::TableRecord> tables;
  std::string note;
  if (r.end == CampaignEnd::completed && j.builder) {
    if (!j.builder->complete()) {
      r.end = CampaignEnd::failed;
      r.reason = "the input ended with " + std::to_string(j.builder->identified_nodes()) + " of " +
                 std::to_string(j.builder->required_nodes()) + " FOT nodes measured";
    } else {
      tables = fot_tables(j, now, note);
    }
  }
  const db::CampaignState state = state_of(r.end);
  const std::string reason = (r.reason.empty() ? std::string("finished") : r.reason) + note;
  const auto campaign = j.campaign, run = r.run_id;
  // Retried: a busy database delays the end of a campaign, it never loses it.
  for (int attempt = 0; attempt < 30; ++attempt) {
    auto ids = writer.call<std::vector<std::int64_t>>(
        [campaign, run, tables, state, reason, now](db::Store& s) { return s.finish_run(campaign, run, tables, state, reason, now); }, 10.0);
    if (ids) {
      if (ids->size() > 0) r.table_id = (*ids)[0];
      if (ids->size() > 1) r.lsq_table_id = (*ids)[1];
      r.reason = reason == "finished" ? "" : reason;
      return r;
    }
  }
  r.reason = reason + "; the database did not take the end of the campaign";
  return r;
}

}  // namespace hystlab::daemon
