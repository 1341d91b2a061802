#include "mqtt_records.hpp"

namespace hystlab::lab::detail {

db::Database& RecordReader::db() {
  // Not synchronous FULL: this connection only reads.
  if (!db_) db_ = std::make_unique<db::Database>(path_, false);
  return *db_;
}

std::int64_t RecordReader::newest_event() {
  db::Statement st(db(), "SELECT coalesce(max(id), 0) FROM events");
  return st.step() ? st.column_int(0) : 0;
}

std::vector<EventRow> RecordReader::events_after(std::int64_t id, int limit) {
  db::Statement st(db(),
                   "SELECT e.id, coalesce(e.campaign_id, 0), coalesce(e.run_id, 0), e.at, e.t, e.kind, coalesce(e.from_state, ''), "
                   "coalesce(e.to_state, ''), coalesce(e.detail, ''), coalesce(r.name, '') FROM events e "
                   "LEFT JOIN campaigns c ON c.id = e.campaign_id LEFT JOIN rigs r ON r.id = c.rig_id WHERE e.id > ? ORDER BY e.id LIMIT ?");
  st.bind(1, id).bind(2, limit);
  std::vector<EventRow> out;
  while (st.step()) {
    EventRow e;
    e.id = st.column_int(0), e.campaign = st.column_int(1), e.run = st.column_int(2);
    e.at = st.column_text(3);
    e.has_t = !st.column_is_null(4);
    e.t = e.has_t ? st.column_double(4) : 0.0;
    e.kind = st.column_text(5), e.from_state = st.column_text(6), e.to_state = st.column_text(7), e.detail = st.column_text(8), e.rig = st.column_text(9);
    out.push_back(std::move(e));
  }
  return out;
}

std::int64_t RecordReader::fot_nodes(std::int64_t campaign) {
  db::Statement st(db(),
                   "SELECT CASE WHEN c.kind = 'fot' THEN (SELECT count(*) FROM fot_nodes n JOIN runs r ON r.id = n.run_id "
                   "WHERE r.campaign_id = c.id) ELSE -1 END FROM campaigns c WHERE c.id = ?");
  st.bind(1, campaign);
  return st.step() ? st.column_int(0) : -1;
}

}  // namespace hystlab::lab::detail
