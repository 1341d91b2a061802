#include "run_finish.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "hystlab/db/sqlite.hpp"
#include "hystlab/models/accuracy.hpp"
#include "hystlab/models/fit_report.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/fot_identification.hpp"
#include "hystlab/models/loop_figures.hpp"
#include "hystlab/models/loop_report.hpp"
#include "hystlab/models/table_score.hpp"

namespace hystlab::daemon {
namespace {
using nlohmann::json;

json evaluate(const models::EverettTable& table, const Columns& s) { return models::accuracy_json(models::score_table(table, s.x, s.f)); }
}  // namespace

void post_evaluation(RunnerContext& ctx, std::int64_t campaign, const models::OnlineTableBuilder& builder, const RunSeries& series, const std::string& now) {
  const auto known = static_cast<std::int64_t>(builder.identified_nodes()), needed = static_cast<std::int64_t>(builder.required_nodes());
  auto work = [&writer = ctx.writer, campaign, table = builder.table(), shared = series.share(), known, needed, now] {
    // On at most 65,536 samples of the run, evenly spread: the final tables are scored on all.
    const Columns few = shared.thinned(kEvaluationSamples);
    domain::CampaignEvent e = domain::FitEvent{known, needed, models::accuracy_json(models::score_table(table, few.x, few.f))};
    writer.post([campaign, e = std::move(e), now](db::Store& s) { s.add_event(campaign, e, now); });
  };
  if (ctx.background)
    ctx.background(std::move(work));
  else
    work();
}

namespace {
// The run's record and the validation run's, contiguous: made on the finisher's thread (the
// acquisition thread hands over its chunks).
struct Record {
  Columns series, validation;
};

// Every closed cycle of the campaign's run (those starting before rows_begin are training loops)
// and of the validation run, with the plan's plateau displacements.
std::vector<db::Store::LoopRecord> loop_records(const FinishJob& j, const Record& rec, std::int64_t run, std::int64_t vrun) {
  std::vector<db::Store::LoopRecord> out;
  models::LoopOptions o;
  o.plateau_at_mm = j.plan.plateaus_mm;
  int k = 0;
  for (const models::LoopFigures& L : models::find_loops(rec.series.x, rec.series.f, o))
    out.push_back({run, k++, L.begin < j.rows_begin ? domain::LoopPhase::training : domain::LoopPhase::rows, models::loop_json(L).dump()});
  if (vrun > 0 && !rec.validation.x.empty()) {
    k = 0;
    for (const models::LoopFigures& L : models::find_loops(rec.validation.x, rec.validation.f, o))
      out.push_back({vrun, k++, domain::LoopPhase::validation, models::loop_json(L).dump()});
  }
  return out;
}

// A table of the campaign, with its accuracy on the campaign's own samples (training figures) and
// on the validation run's (held-out figures, when there is one).
struct Candidate {
  std::string label;
  db::Store::TableRecord record;
  models::TableProvenance provenance;
  models::EverettTable table;
  json accuracy;
  std::optional<double> heldout_rms;
};

Candidate candidate(const FinishJob& j, const Record& rec, std::string label, std::string method, int n, const models::EverettTable& table,
                    models::TableProvenance prov) {
  Candidate c{std::move(label), {std::move(method), n, j.plan.lo_mm, j.plan.hi_mm, "", ""}, std::move(prov), table, evaluate(table, rec.series), {}};
  if (rec.validation.x.size() >= 2) {
    json held = evaluate(table, rec.validation);
    c.heldout_rms = held.at("overall").at("rms_N").get<double>();
    c.accuracy["held_out"] = std::move(held);
  }
  return c;
}

// The recommended table: the lowest RMS error on the validation run; the reason lists them all.
std::string recommend(std::vector<Candidate>& cs) {
  std::optional<std::size_t> best;
  for (std::size_t k = 0; k < cs.size(); ++k)
    if (cs[k].heldout_rms && (!best || *cs[k].heldout_rms < *cs[*best].heldout_rms)) best = k;
  if (!best) return "";
  auto newtons = [](double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.3g N", v);
    return std::string(b);
  };
  std::string why = cs[*best].label + " has the lowest error on the validation run (held-out RMS";
  for (const Candidate& c : cs)
    if (c.heldout_rms) why += (&c == &cs.front() ? " " : "; ") + c.label + ": " + newtons(*c.heldout_rms);
  why += ")";
  for (std::size_t k = 0; k < cs.size(); ++k) {
    cs[k].accuracy["recommended"] = k == *best;
    if (k == *best) cs[k].accuracy["recommendation"] = why;
  }
  return why;
}

// The fot tables of a finished campaign: the calibrated table from every node, and the
// least-squares table (prior decided by held-out blocks), each with its accuracy on every sample
// of the campaign's runs, on the validation run, drift and provenance.
std::vector<db::Store::TableRecord> fot_tables(FinishJob& j, const Record& rec, const std::string& now, std::string& note, std::string& recommendation) {
  const domain::Plan& plan = j.plan;
  const models::DriftReport drift = models::drift_report(*j.builder);
  const std::string source = "campaign " + std::to_string(j.campaign), run = "run " + std::to_string(j.result.run_id);
  // The table's own grid: the plan's, or the rows an adaptive design measured.
  const models::Grid& grid = j.builder->grid();
  const std::string fot_label = std::string(plan.design.adaptive ? "fot adaptive" : "fot") + " n=" + std::to_string(grid.n);
  std::vector<Candidate> cs;
  cs.push_back(candidate(j, rec, fot_label, "fot", grid.n, j.builder->table(),
                         {source, "fot", now, run, {{"drift_max_spread_N", drift.max_spread}, {"drift_pooled_std_N", drift.pooled_std}}}));
  // At most n = 24 on a plan's grid, as before: the campaign's end (and a shutdown) waits for it
  // and the fit cannot be cancelled yet. A grid of its own is fitted on its own nodes (beyond
  // n = 24, 24 uniform steps). An adaptive design's grid is its point: fitted as it is up to
  // n = 48 (bench_fit, stop 42: 2.4 s on 10^5 samples).
  const int cap = plan.design.adaptive ? 48 : 24;
  const int n = std::min(grid.n, cap);
  const models::Grid lsq_grid = n == grid.n ? grid : models::Grid::make(plan.lo_mm, plan.hi_mm, n);
  try {
    const models::PreisachFitResult fit = models::fit_preisach(rec.series.x, rec.series.f, lsq_grid);
    cs.push_back(candidate(j, rec, "lsq " + std::string(models::to_string(fit.chosen.prior)) + " n=" + std::to_string(n), "lsq", n, fit.chosen.table,
                           {source, "lsq", now, run, models::fit_provenance(fit)}));
  } catch (const std::exception& e) {  // optional: its failure never costs the campaign its fot table
    note = std::string("; least-squares table skipped: ") + e.what();
  }
  recommendation = recommend(cs);
  std::vector<db::Store::TableRecord> out;
  for (Candidate& c : cs) {
    c.provenance.extra["accuracy"] = c.accuracy;
    c.record.accuracy_json = c.accuracy.dump();
    c.record.document_json = models::table_to_json(c.table, c.provenance).dump();
    out.push_back(std::move(c.record));
  }
  return out;
}
}  // namespace

RunnerResult finish_campaign(FinishJob j, db::SampleWriter& writer, const std::function<std::string()>& now_iso) {
  RunnerResult r = j.result;
  const std::string now = now_iso();
  db::Store::RunEnd end;
  std::string note, recommendation;
  const Record rec{j.series.columns(), j.validation.columns()};
  if (r.end == CampaignEnd::completed && j.builder) {
    if (!j.builder->complete()) {
      r.end = CampaignEnd::failed;
      r.reason = "the input ended with " + std::to_string(j.builder->identified_nodes()) + " of " + std::to_string(j.builder->required_nodes()) +
                 " FOT nodes measured";
    } else {
      end.tables = fot_tables(j, rec, now, note, recommendation);
      for (std::size_t k = 0; k < end.tables.size(); ++k)
        if (json::parse(end.tables[k].accuracy_json).value("recommended", false)) end.recommended = k;
      end.recommendation = recommendation;
    }
  }
  if (j.plan.kind == domain::CampaignKind::sine && j.isolator && !j.sine_steps.empty()) {
    try {  // the isolator model at the measured amplitudes, in the order the rig took them
      std::vector<PredictStep> steps;
      for (const auto& [k, step] : j.sine_steps) steps.push_back(step);
      const std::vector<Predicted> p = predict_sweep(*j.isolator, steps);
      for (std::size_t k = 0; k < p.size(); ++k) end.predictions.push_back({j.sine_steps[k].first, p[k].ratio, p[k].phase_rad});
    } catch (const std::exception& e) {  // a prediction is extra: it never costs the campaign its end
      note += std::string("; no prediction: ") + e.what();
    }
  }
  if (j.plan.kind != domain::CampaignKind::sine) {
    try {
      end.loops = loop_records(j, rec, r.run_id, r.validation_run_id);
    } catch (const std::exception& e) {  // figures are extra: they never cost the campaign its end
      note += std::string("; loop figures skipped: ") + e.what();
    }
  }
  end.campaign = j.campaign;
  end.run = r.run_id;
  end.validation_run = r.validation_run_id;
  end.state = state_of(r.end);
  end.reason = (r.reason.empty() ? std::string("finished") : r.reason) + note;
  end.now = now;
  // Retried: a busy database delays the end of a campaign, it never loses it. An end the database
  // refuses outright (a constraint, a full disk) is retried a few times, then the campaign is
  // failed with that reason, without its tables: its samples stay, and it is never left 'queued'
  // or 'running' (stop 25's resumes stayed queued for ever when the tables had no run).
  // The job's state is shared with it, not borrowed: a call that timed out leaves its job queued,
  // and it may run after this function has returned.
  struct Attempt {
    db::Store::RunEnd end;
    std::mutex mu;  // refused and busy: written by the writer thread, read here
    std::string refused;
    bool busy = false;  // SQLITE_BUSY or SQLITE_LOCKED: another connection's lock, retried like a timeout
    void failed(const std::string& what, bool is_busy) {
      std::lock_guard lk(mu);
      refused = what, busy = is_busy;
    }
    std::pair<std::string, bool> why() {
      std::lock_guard lk(mu);
      return {refused, busy};
    }
  };
  const auto a = std::make_shared<Attempt>();
  a->end = std::move(end);
  for (int attempt = 0; attempt < 30; ++attempt) {
    auto ids = writer.call<std::vector<std::int64_t>>(
        [a](db::Store& s) {
          try {
            return s.finish_run(a->end);
          } catch (const db::DbError& e) {
            a->failed(e.what(), (e.code & 0xff) == 5 || (e.code & 0xff) == 6);
            throw;
          } catch (const std::exception& e) {
            a->failed(e.what(), false);
            throw;
          }
        },
        10.0);
    if (ids) {
      if (ids->size() > 0) r.table_id = (*ids)[0];
      if (ids->size() > 1) r.lsq_table_id = (*ids)[1];
      r.reason = a->end.reason == "finished" ? "" : a->end.reason;
      return r;
    }
    const auto [refused, busy] = a->why();
    if (!refused.empty() && !busy && attempt >= 2) break;
    if (busy) std::this_thread::sleep_for(std::chrono::milliseconds(100 * (attempt + 1)));
  }
  const std::string refused = a->why().first;
  r.end = CampaignEnd::failed;
  r.reason = a->end.reason + "; the database did not take the end of the campaign" + (refused.empty() ? std::string() : " (" + refused + ")");
  const std::string reason = r.reason;
  const auto id = j.campaign;
  const auto last = writer.call<int>(
      [id, reason, now](db::Store& s) {
        s.transition(id, domain::CampaignState::failed, reason, now);
        return 0;
      },
      10.0);
  if (!last) r.reason += "; nor its failure";
  return r;
}

}  // namespace hystlab::daemon
