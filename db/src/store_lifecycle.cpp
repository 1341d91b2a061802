// The store's campaign life cycle beyond single rows: finishing a run in one transaction,
// holding what a restart found queued, the rigs' names and I/O statistics.
#include "hystlab/db/store.hpp"

#include <algorithm>

namespace hystlab::db {
void records_changed() noexcept;  // store.cpp

int Lifecycle::hold_queued(const std::string& now) {
  std::vector<std::int64_t> ids;
  {
    Statement st(db_, "SELECT id FROM campaigns WHERE state = 'queued' ORDER BY id");
    while (st.step()) ids.push_back(st.column_int(0));
  }
  for (auto id : ids) transition(id, domain::CampaignState::held, "held after restart: nothing moves until an operator releases it (resume)", now);
  return static_cast<int>(ids.size());
}

std::int64_t Reads::table_count(std::int64_t campaign) {
  Statement st(db_, "SELECT count(*) FROM tables WHERE campaign_id = ?");
  st.bind(1, campaign);
  st.step();
  return st.column_int(0);
}

std::vector<std::int64_t> Reads::runs_of_campaign(std::int64_t campaign, std::optional<domain::RunRole> role) {
  std::vector<std::int64_t> out;
  Statement st(db_, role ? "SELECT id FROM runs WHERE campaign_id = ? AND role = ? ORDER BY id" : "SELECT id FROM runs WHERE campaign_id = ? ORDER BY id");
  st.bind(1, campaign);
  if (role) st.bind(2, std::string_view(to_string(*role)));
  while (st.step()) out.push_back(st.column_int(0));
  return out;
}

std::vector<std::int64_t> Lifecycle::finish_run(const RunEnd& e) {
  std::vector<std::int64_t> ids;
  Transaction tx(db_);
  for (const RunEnd::Prediction& p : e.predictions) {
    Statement st(db_, "UPDATE transmissibility SET predicted_ratio = ?, predicted_phase_rad = ? WHERE run_id = ? AND step = ?");
    st.bind(1, p.ratio).bind(2, p.phase_rad).bind(3, e.run).bind(4, p.step);
    st.step();
  }
  if (reads_.table_count(e.campaign) == 0) {
    for (const TableRecord& t : e.tables) ids.push_back(add_table(e.campaign, e.run, t.method, t.n, t.lo, t.hi, e.now, t.accuracy_json, t.document_json));
    if (e.recommended && *e.recommended < ids.size()) {
      const TableRecord& t = e.tables[*e.recommended];
      add_event(e.campaign, domain::RecommendationEvent{ids[*e.recommended], t.n, t.method, e.recommendation}, e.now);
    }
  }
  for (const LoopRecord& l : e.loops) {
    Statement st(db_, "INSERT OR REPLACE INTO loops(run_id, k, phase, figures) VALUES(?,?,?,?)");
    st.bind(1, l.run).bind(2, static_cast<std::int64_t>(l.k)).bind(3, std::string_view(to_string(l.phase))).bind(4, l.figures_json);
    st.step();
  }
  if (e.run > 0) end_run(e.run, e.state, e.now);
  if (e.validation_run > 0) {
    // A validation run with loop figures is kept even when its samples were lost (a full writer
    // ring): the figures reference it (the safety matrix's "ring full" cells failed the campaign
    // with a FOREIGN KEY error here).
    const bool has_loops = std::any_of(e.loops.begin(), e.loops.end(), [&e](const LoopRecord& l) { return l.run == e.validation_run; });
    if (has_loops || reads_.sample_count(e.validation_run) > 0) {
      end_run(e.validation_run, e.state, e.now);
    } else {  // never started (the campaign ended before it): no empty run is left behind
      Statement del(db_, "DELETE FROM runs WHERE id = ? AND NOT EXISTS (SELECT 1 FROM samples WHERE run_id = ?)");
      del.bind(1, e.validation_run).bind(2, e.validation_run);
      del.step();
    }
  }
  transition_in(e.campaign, e.state, e.reason, e.now);
  tx.commit();
  records_changed();
  return ids;
}

std::vector<std::string> Reads::rig_names() {
  std::vector<std::string> out;
  Statement st(db_, "SELECT name FROM rigs ORDER BY id");
  while (st.step()) out.push_back(st.column_text(0));
  return out;
}

void Lifecycle::add_io_stats(std::int64_t rig, const std::string& stats, const std::string& now) {
  Statement st(db_, "INSERT INTO io_stats(rig_id, at, stats) VALUES(?,?,?)");
  st.bind(1, rig).bind(2, now).bind(3, stats);
  st.step();
}

}  // namespace hystlab::db
