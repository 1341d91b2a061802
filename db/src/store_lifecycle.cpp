// The store's campaign life cycle beyond single rows: finishing a run in one transaction,
// holding what a restart found queued, the rigs' names and I/O statistics.
#include "hystlab/db/store.hpp"

namespace hystlab::db {
void records_changed() noexcept;  // store.cpp

int Store::hold_queued(const std::string& now) {
  std::vector<std::int64_t> ids;
  {
    Statement st(db_, "SELECT id FROM campaigns WHERE state = 'queued' ORDER BY id");
    while (st.step()) ids.push_back(st.column_int(0));
  }
  for (auto id : ids) transition(id, CampaignState::held, "held after restart: nothing moves until an operator releases it (resume)", now);
  return static_cast<int>(ids.size());
}

std::int64_t Store::table_count(std::int64_t campaign) {
  Statement st(db_, "SELECT count(*) FROM tables WHERE campaign_id = ?");
  st.bind(1, campaign);
  st.step();
  return st.column_int(0);
}

std::vector<std::int64_t> Store::runs_of_campaign(std::int64_t campaign) {
  std::vector<std::int64_t> out;
  Statement st(db_, "SELECT id FROM runs WHERE campaign_id = ? ORDER BY id");
  st.bind(1, campaign);
  while (st.step()) out.push_back(st.column_int(0));
  return out;
}

std::vector<std::int64_t> Store::finish_run(std::int64_t campaign, std::int64_t run, const std::vector<TableRecord>& tables,
                                            CampaignState state, const std::string& reason, const std::string& now) {
  std::vector<std::int64_t> ids;
  Transaction tx(db_);
  if (table_count(campaign) == 0)
    for (const TableRecord& t : tables) ids.push_back(add_table(campaign, run, t.method, t.n, t.lo, t.hi, now, t.accuracy_json, t.document_json));
  if (run > 0) end_run(run, state, now);
  transition_in(campaign, state, reason, now);
  tx.commit();
  records_changed();
  return ids;
}

std::vector<std::string> Store::rig_names() {
  std::vector<std::string> out;
  Statement st(db_, "SELECT name FROM rigs ORDER BY id");
  while (st.step()) out.push_back(st.column_text(0));
  return out;
}

void Store::add_io_stats(std::int64_t rig, const std::string& stats, const std::string& now) {
  Statement st(db_, "INSERT INTO io_stats(rig_id, at, stats) VALUES(?,?,?)");
  st.bind(1, rig).bind(2, now).bind(3, stats);
  st.step();
}

}  // namespace hystlab::db
