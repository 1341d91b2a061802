// What the API and the CLI read (store.hpp, "reads"): one statement each, rows as value types.
#include <stdexcept>

#include "hystlab/db/store.hpp"

namespace hystlab::db {
namespace {
constexpr const char* kRunSelect =
    "SELECT id, campaign_id, state, started_at, coalesce(ended_at, ''), wall_anchor_unix, "
    "(SELECT coalesce(sum(n), 0) FROM sample_blocks WHERE run_id = runs.id), (SELECT count(*) FROM fot_nodes WHERE run_id = runs.id), role FROM runs ";
constexpr const char* kTableSelect = "SELECT id, campaign_id, run_id, method, n, range_lo, range_hi, created_at, coalesce(accuracy, '') FROM tables ";
constexpr const char* kNodeSelect =
    "SELECT f.id, r.campaign_id, f.run_id, alpha, beta, force_alpha, force_alpha_beta, coalesce(f.t, 0) FROM fot_nodes f JOIN runs r ON r.id = f.run_id ";

RunInfo run_row(Statement& st) {
  return {st.column_int(0),    st.column_int(1), st.column_text(2), st.column_text(3), st.column_text(4),
          st.column_double(5), st.column_int(6), st.column_int(7),  st.column_text(8)};
}
TableInfo table_row(Statement& st) {
  TableInfo t;
  t.id = st.column_int(0);
  if (!st.column_is_null(1)) t.campaign = st.column_int(1);
  if (!st.column_is_null(2)) t.run = st.column_int(2);
  t.method = st.column_text(3), t.n = st.column_int(4), t.range_lo = st.column_double(5), t.range_hi = st.column_double(6);
  t.created_at = st.column_text(7), t.accuracy_json = st.column_text(8);
  return t;
}
NodeInfo node_row(Statement& st) {
  return {st.column_int(0),    st.column_int(1),    st.column_int(2),    st.column_double(3),
          st.column_double(4), st.column_double(5), st.column_double(6), st.column_double(7)};
}
template <class Row, class F>
std::vector<Row> all(Statement& st, F row) {
  std::vector<Row> out;
  while (st.step()) out.push_back(row(st));
  return out;
}
}  // namespace

std::pair<std::string, std::string> Reads::rig_record(std::int64_t rig_id) {
  Statement st(db_, "SELECT name, config FROM rigs WHERE id = ?");
  st.bind(1, rig_id);
  if (!st.step()) return {"", "{}"};
  return {st.column_text(0), st.column_text(1)};
}

std::string Reads::rig_name(std::int64_t rig_id) {
  Statement st(db_, "SELECT name FROM rigs WHERE id = ?");
  st.bind(1, rig_id);
  return st.step() ? st.column_text(0) : std::string();
}

std::vector<std::pair<std::int64_t, std::string>> Reads::rigs() {
  Statement st(db_, "SELECT id, name FROM rigs ORDER BY id");
  return all<std::pair<std::int64_t, std::string>>(st, [](Statement& s) { return std::make_pair(s.column_int(0), s.column_text(1)); });
}

std::vector<std::pair<domain::CampaignState, std::int64_t>> Reads::campaign_counts() {
  Statement st(db_, "SELECT state, count(*) FROM campaigns GROUP BY state");
  return all<std::pair<domain::CampaignState, std::int64_t>>(st, [](Statement& s) {
    const std::string text = s.column_text(0);
    const auto state = domain::campaign_state_from(text);
    if (!state) throw DbError("unknown campaign state '" + text + "' in the database", 0);
    return std::make_pair(*state, s.column_int(1));
  });
}

std::optional<RunInfo> Reads::run(std::int64_t id) {
  Statement st(db_, std::string(kRunSelect) + "WHERE id = ?");
  st.bind(1, id);
  if (!st.step()) return std::nullopt;
  return run_row(st);
}

std::vector<RunInfo> Reads::runs(std::int64_t campaign) {
  Statement st(db_, std::string(kRunSelect) + "WHERE campaign_id = ? ORDER BY id");
  st.bind(1, campaign);
  return all<RunInfo>(st, run_row);
}

std::optional<std::pair<double, double>> Reads::time_span(std::int64_t run) {
  Statement st(db_, "SELECT min(t_min), max(t_max) FROM sample_blocks WHERE run_id = ?");
  st.bind(1, run);
  st.step();
  if (st.column_is_null(0)) return std::nullopt;
  return std::make_pair(st.column_double(0), st.column_double(1));
}

std::vector<TableInfo> Reads::tables(std::optional<std::int64_t> campaign) {
  Statement st(db_, std::string(kTableSelect) + (campaign ? "WHERE campaign_id = ? ORDER BY id" : "ORDER BY id"));
  if (campaign) st.bind(1, *campaign);
  return all<TableInfo>(st, table_row);
}

std::optional<TableInfo> Reads::table(std::int64_t id) {
  Statement st(db_, std::string(kTableSelect) + "WHERE id = ?");
  st.bind(1, id);
  if (!st.step()) return std::nullopt;
  return table_row(st);
}

std::optional<std::string> Reads::table_document(std::int64_t id) {
  Statement st(db_, "SELECT document FROM tables WHERE id = ?");
  st.bind(1, id);
  if (!st.step()) return std::nullopt;
  return st.column_text(0);
}

namespace {
// The newest table of a method among those `owner` selects (a campaign id, or a rig's campaigns).
std::optional<TableInfo> newest_table(Database& db, const char* owner, std::int64_t id, const std::string& method) {
  Statement st(db, std::string(kTableSelect) + "WHERE method = ? AND " + owner + " ORDER BY id DESC LIMIT 1");
  st.bind(1, method);
  st.bind(2, id);
  if (!st.step()) return std::nullopt;
  return table_row(st);
}
}  // namespace

std::optional<TableInfo> Reads::newest_table_of_rig(std::int64_t rig_id, const std::string& method) {
  return newest_table(db_, "campaign_id IN (SELECT id FROM campaigns WHERE rig_id = ?)", rig_id, method);
}

std::optional<TableInfo> Reads::newest_table_of_campaign(std::int64_t campaign_id, const std::string& method) {
  return newest_table(db_, "campaign_id = ?", campaign_id, method);
}

std::vector<NodeInfo> Reads::nodes(std::int64_t campaign) {
  Statement st(db_, std::string(kNodeSelect) + "WHERE r.campaign_id = ? ORDER BY f.id");
  st.bind(1, campaign);
  return all<NodeInfo>(st, node_row);
}

std::vector<TransmissibilityInfo> Reads::transmissibility(std::int64_t campaign) {
  Statement st(db_,
               "SELECT t.id, t.run_id, frequency_hz, coalesce(base_amplitude_mm, 0), coalesce(mass_amplitude_mm, 0), coalesce(ratio, 0), "
               "coalesce(phase_rad, 0), coalesce(step, 0), coalesce(demand_mm, 0), coalesce(direction, ''), coalesce(detail, ''), "
               "predicted_ratio, predicted_phase_rad FROM transmissibility t JOIN runs r ON r.id = t.run_id WHERE r.campaign_id = ? ORDER BY t.id");
  st.bind(1, campaign);
  return all<TransmissibilityInfo>(st, [](Statement& s) {
    TransmissibilityInfo t{s.column_int(0),    s.column_int(1), s.column_double(2), s.column_double(3), s.column_double(4), s.column_double(5),
                           s.column_double(6), s.column_int(7), s.column_double(8), s.column_text(9),   s.column_text(10)};
    if (!s.column_is_null(11)) t.predicted_ratio = s.column_double(11), t.predicted_phase_rad = s.column_double(12);
    return t;
  });
}

std::vector<std::string> Reads::event_details(std::int64_t campaign, const std::string& kind) {
  Statement st(db_, "SELECT coalesce(detail, '') FROM events WHERE campaign_id = ? AND kind = ? ORDER BY id");
  st.bind(1, campaign);
  st.bind(2, kind);
  return all<std::string>(st, [](Statement& s) { return s.column_text(0); });
}

std::string Reads::state_reason(std::int64_t campaign, domain::CampaignState state) {
  Statement st(db_, "SELECT coalesce(detail, '') FROM events WHERE campaign_id = ? AND kind = 'state' AND to_state = ? ORDER BY id DESC LIMIT 1");
  st.bind(1, campaign);
  st.bind(2, std::string_view(to_string(state)));
  return st.step() ? st.column_text(0) : std::string();
}

std::vector<EventInfo> Reads::events_after(std::int64_t id, int limit) {
  Statement st(db_,
               "SELECT id, coalesce(campaign_id, 0), at, kind, coalesce(from_state, ''), coalesce(to_state, ''), coalesce(detail, '') "
               "FROM events WHERE id > ? ORDER BY id LIMIT ?");
  st.bind(1, id);
  st.bind(2, static_cast<std::int64_t>(limit));
  return all<EventInfo>(st, [](Statement& s) {
    return EventInfo{s.column_int(0), s.column_int(1), s.column_text(2), s.column_text(3), s.column_text(4), s.column_text(5), s.column_text(6)};
  });
}

std::vector<NodeInfo> Reads::nodes_after(std::int64_t id, int limit) {
  Statement st(db_, std::string(kNodeSelect) + "WHERE f.id > ? ORDER BY f.id LIMIT ?");
  st.bind(1, id);
  st.bind(2, static_cast<std::int64_t>(limit));
  return all<NodeInfo>(st, node_row);
}

std::vector<TableInfo> Reads::tables_after(std::int64_t id, int limit) {
  Statement st(db_, std::string(kTableSelect) + "WHERE id > ? ORDER BY id LIMIT ?");
  st.bind(1, id);
  st.bind(2, static_cast<std::int64_t>(limit));
  return all<TableInfo>(st, table_row);
}

std::int64_t Reads::newest_id(const std::string& table) {
  if (table != "events" && table != "fot_nodes" && table != "tables") throw std::invalid_argument("newest_id: no table '" + table + "'");
  Statement st(db_, "SELECT coalesce(max(id), 0) FROM " + table);
  st.step();
  return st.column_int(0);
}

std::int64_t Reads::read_xy(std::int64_t run, std::int64_t seq0, bool base_mass, std::vector<float>& x, std::vector<float>& y) {
  Statement st(db_, base_mass ? "SELECT seq, base_displacement_mm, mass_displacement_mm FROM shaker_samples WHERE run_id = ? AND seq >= ? ORDER BY seq"
                              : "SELECT seq, disp, force FROM samples WHERE run_id = ? AND seq >= ? ORDER BY seq");
  st.bind(1, run);
  st.bind(2, seq0);
  std::int64_t next = seq0;
  while (st.step()) {
    next = st.column_int(0) + 1;
    x.push_back(static_cast<float>(st.column_double(1)));
    y.push_back(static_cast<float>(st.column_double(2)));
  }
  return next;
}

std::vector<LoopInfo> Reads::loops(std::int64_t campaign) {
  Statement st(db_, "SELECT l.run_id, l.k, l.phase, l.figures FROM loops l JOIN runs r ON r.id = l.run_id WHERE r.campaign_id = ? ORDER BY l.run_id, l.k");
  st.bind(1, campaign);
  return all<LoopInfo>(st, [](Statement& s) { return LoopInfo{s.column_int(0), s.column_int(1), s.column_text(2), s.column_text(3)}; });
}

}  // namespace hystlab::db
