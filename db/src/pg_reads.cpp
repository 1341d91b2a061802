// One daemon's records from the lab database (pg_reads.hpp): store_reads.cpp's queries, asked
// of hystlab.* for one daemon_id ($1 in every statement).
#include "hystlab/db/pg_reads.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <limits>

#include "hystlab/db/sqlite.hpp"
#include "pg_values.hpp"

namespace hystlab::db {
namespace {
// A time as the daemon's file holds it: ISO 8601 in UTC with milliseconds (daemon/src/clock.cpp).
std::string iso(const std::string& col) { return "coalesce(to_char(" + col + " AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI:SS.MS\"Z\"'), '')"; }
// A double as a parameter, exactly (std::to_string keeps six decimals).
std::string exact(double v) {
  std::array<char, 32> buf{};
  std::snprintf(buf.data(), buf.size(), "%.17g", v);
  return buf.data();
}

const std::string kCampaignSelect = "SELECT id, coalesce(rig_id, 0), coalesce(kind, ''), coalesce(plan::text, '{}'), coalesce(state, ''), " +
                                    iso("created_at") + ", " + iso("updated_at") + " FROM hystlab.campaigns WHERE daemon_id = $1";
CampaignRow campaign_row(const PgResult& r, int k) {
  CampaignRow c;
  c.id = r.integer(k, 0), c.rig_id = r.integer(k, 1);
  const std::string kind = r.text(k, 2), state = r.text(k, 4);
  const auto ck = domain::campaign_kind_from(kind);
  const auto cs = domain::campaign_state_from(state);
  if (!ck) throw DbError("campaign " + std::to_string(c.id) + ": unknown kind '" + kind + "' in the lab database", 0);
  if (!cs) throw DbError("campaign " + std::to_string(c.id) + ": unknown state '" + state + "' in the lab database", 0);
  c.kind = *ck, c.state = *cs, c.plan = r.text(k, 3), c.created_at = r.text(k, 5), c.updated_at = r.text(k, 6);
  return c;
}

// A run's samples are those replicated: its mark in either samples table (the daemon's file
// counts its block summaries; the two agree once the run is caught up).
const std::string kRunSelect =
    "SELECT u.id, coalesce(u.campaign_id, 0), coalesce(u.state, ''), " + iso("u.started_at") + ", " + iso("u.ended_at") +
    ", coalesce(u.wall_anchor_unix, 0), coalesce((SELECT max(m.mark) + 1 FROM hystlab.marks m WHERE m.daemon_id = u.daemon_id "
    "AND m.tbl IN ('samples', 'shaker_samples') AND m.key = u.id), 0), (SELECT count(*) FROM hystlab.fot_nodes f WHERE f.daemon_id = u.daemon_id "
    "AND f.run_id = u.id), coalesce(u.role, 'campaign') FROM hystlab.runs u WHERE u.daemon_id = $1 ";
RunInfo run_row(const PgResult& r, int k) {
  return {r.integer(k, 0), r.integer(k, 1), r.text(k, 2), r.text(k, 3), r.text(k, 4), pg_num(r, k, 5), r.integer(k, 6), r.integer(k, 7), r.text(k, 8)};
}

const std::string kTableSelect = "SELECT id, campaign_id, run_id, coalesce(method, ''), coalesce(n, 0), coalesce(range_lo, 0), coalesce(range_hi, 0), " +
                                 iso("created_at") + ", coalesce(accuracy, '') FROM hystlab.tables WHERE daemon_id = $1 ";

const std::string kNodeSelect =
    "SELECT f.id, coalesce(u.campaign_id, 0), f.run_id, coalesce(f.alpha, 0), coalesce(f.beta, 0), coalesce(f.force_alpha, 0), "
    "coalesce(f.force_alpha_beta, 0), coalesce(f.t, 0) FROM hystlab.fot_nodes f "
    "JOIN hystlab.runs u ON u.daemon_id = f.daemon_id AND u.id = f.run_id WHERE f.daemon_id = $1 ";

constexpr std::array<const char*, 6> kShakerValues = {"drive_frequency_hz",   "drive_amplitude_mm", "base_displacement_mm",
                                                      "mass_displacement_mm", "base_accel_m_s2",    "mass_accel_m_s2"};

// Every row of a run's samples with seq in [seq0, seq1], in seq order, in chunks of 50,000 (a
// run of any length in bounded memory; each chunk one indexed range of the run's partition).
template <class F>
void chunked(const std::function<PgResult(const std::string&, const std::string&)>& q, std::int64_t seq0, std::int64_t seq1, F f) {
  std::int64_t from = seq0;
  while (from <= seq1) {
    const PgResult r = q(std::to_string(from), std::to_string(seq1));
    if (r.rows() == 0) return;
    for (int k = 0; k < r.rows(); ++k) f(r, k);
    const std::int64_t last = r.integer(r.rows() - 1, 0);
    if (last == std::numeric_limits<std::int64_t>::max()) return;
    from = last + 1;
  }
}
}  // namespace

std::optional<int> PgReads::daemon_id(PgConnection& pg, const std::string& lab, const std::string& daemon) {
  const PgResult r = pg.query("SELECT id FROM hystlab.daemons WHERE lab = $1 AND name = $2", {lab.c_str(), daemon.c_str()});
  if (r.rows() == 0) return std::nullopt;
  return static_cast<int>(r.integer(0, 0));
}

PgResult PgReads::query(const std::string& sql, const std::vector<std::string>& more) {
  std::vector<const char*> params{daemon_.c_str()};
  for (const std::string& p : more) params.push_back(p.c_str());
  return pg_.query(sql, params);
}

std::optional<CampaignRow> PgReads::campaign(std::int64_t id) {
  const PgResult r = query(kCampaignSelect + " AND id = $2", {std::to_string(id)});
  if (r.rows() == 0) return std::nullopt;
  return campaign_row(r, 0);
}

std::vector<CampaignRow> PgReads::campaigns() {
  const PgResult r = query(kCampaignSelect + " ORDER BY id");
  std::vector<CampaignRow> out;
  for (int k = 0; k < r.rows(); ++k) out.push_back(campaign_row(r, k));
  return out;
}

std::vector<EventRow> PgReads::events(std::int64_t campaign_id) {
  const PgResult r = query("SELECT id, " + iso("at") +
                               ", coalesce(kind, ''), coalesce(from_state, ''), coalesce(to_state, ''), coalesce(detail, '') "
                               "FROM hystlab.events WHERE daemon_id = $1 AND campaign_id = $2 ORDER BY id",
                           {std::to_string(campaign_id)});
  std::vector<EventRow> out;
  for (int k = 0; k < r.rows(); ++k) out.push_back({r.integer(k, 0), r.text(k, 1), r.text(k, 2), r.text(k, 3), r.text(k, 4), r.text(k, 5)});
  return out;
}

std::vector<std::string> PgReads::event_details(std::int64_t campaign_id, const std::string& kind) {
  const PgResult r = query("SELECT coalesce(detail, '') FROM hystlab.events WHERE daemon_id = $1 AND campaign_id = $2 AND kind = $3 ORDER BY id",
                           {std::to_string(campaign_id), kind});
  std::vector<std::string> out;
  for (int k = 0; k < r.rows(); ++k) out.push_back(r.text(k, 0));
  return out;
}

std::string PgReads::state_reason(std::int64_t campaign_id, domain::CampaignState state) {
  const PgResult r = query(
      "SELECT coalesce(detail, '') FROM hystlab.events WHERE daemon_id = $1 AND campaign_id = $2 AND kind = 'state' AND to_state = $3 "
      "ORDER BY id DESC LIMIT 1",
      {std::to_string(campaign_id), domain::to_string(state)});
  return r.rows() ? r.text(0, 0) : std::string();
}

std::string PgReads::rig_name(std::int64_t rig_id) { return rig_record(rig_id).first; }

std::pair<std::string, std::string> PgReads::rig_record(std::int64_t rig_id) {
  const PgResult r = query("SELECT name, coalesce(config::text, '{}') FROM hystlab.rigs WHERE daemon_id = $1 AND id = $2", {std::to_string(rig_id)});
  if (r.rows() == 0) return {"", "{}"};
  return {r.text(0, 0), r.text(0, 1)};
}

std::vector<std::pair<std::int64_t, std::string>> PgReads::rigs() {
  const PgResult r = query("SELECT id, name FROM hystlab.rigs WHERE daemon_id = $1 ORDER BY id");
  std::vector<std::pair<std::int64_t, std::string>> out;
  for (int k = 0; k < r.rows(); ++k) out.emplace_back(r.integer(k, 0), r.text(k, 1));
  return out;
}

std::optional<RunInfo> PgReads::run(std::int64_t id) {
  const PgResult r = query(kRunSelect + "AND u.id = $2", {std::to_string(id)});
  if (r.rows() == 0) return std::nullopt;
  return run_row(r, 0);
}

std::vector<RunInfo> PgReads::runs(std::int64_t campaign_id) {
  const PgResult r = query(kRunSelect + "AND u.campaign_id = $2 ORDER BY u.id", {std::to_string(campaign_id)});
  std::vector<RunInfo> out;
  for (int k = 0; k < r.rows(); ++k) out.push_back(run_row(r, k));
  return out;
}

std::vector<std::int64_t> PgReads::runs_of_campaign(std::int64_t campaign_id, std::optional<domain::RunRole> role) {
  const PgResult r = query("SELECT id FROM hystlab.runs WHERE daemon_id = $1 AND campaign_id = $2 AND ($3 = '' OR role = $3) ORDER BY id",
                           {std::to_string(campaign_id), role ? domain::to_string(*role) : ""});
  std::vector<std::int64_t> out;
  for (int k = 0; k < r.rows(); ++k) out.push_back(r.integer(k, 0));
  return out;
}

std::optional<std::pair<double, double>> PgReads::time_span(std::int64_t run_id) {
  // Through the primary key from both ends (two index probes), in whichever table holds the run.
  for (const char* table : {"hystlab.samples", "hystlab.shaker_samples"}) {
    const std::string t(table);
    const PgResult r = query("SELECT (SELECT t FROM " + t + " WHERE daemon_id = $1 AND run_id = $2 ORDER BY seq LIMIT 1), (SELECT t FROM " + t +
                                 " WHERE daemon_id = $1 AND run_id = $2 ORDER BY seq DESC LIMIT 1)",
                             {std::to_string(run_id)});
    if (!r.is_null(0, 0)) return std::make_pair(pg_num(r, 0, 0), pg_num(r, 0, 1));
  }
  return std::nullopt;
}

std::int64_t PgReads::sample_count(std::int64_t run_id) { return std::max(max_seq(run_id), max_shaker_seq(run_id)) + 1; }

std::int64_t PgReads::max_seq(std::int64_t run_id) {
  return query("SELECT coalesce(max(seq), -1) FROM hystlab.samples WHERE daemon_id = $1 AND run_id = $2", {std::to_string(run_id)}).integer(0, 0);
}

std::int64_t PgReads::max_shaker_seq(std::int64_t run_id) {
  return query("SELECT coalesce(max(seq), -1) FROM hystlab.shaker_samples WHERE daemon_id = $1 AND run_id = $2", {std::to_string(run_id)}).integer(0, 0);
}

// The server buckets by time as the file's overview does (bucket k of n holds t0 + [k, k+1) of
// the span, the last one closed), each bucket's minima and maxima: one query, every peak kept.
std::vector<Bucket> PgReads::overview(std::int64_t run_id, double t0, double t1, int buckets, bool shaker) {
  const int n = std::max(1, buckets);
  const double span = t1 > t0 ? t1 - t0 : 1.0;
  const std::string d = shaker ? "base_displacement_mm" : "disp", f = shaker ? "mass_displacement_mm" : "force";
  const std::string table = shaker ? "hystlab.shaker_samples" : "hystlab.samples";
  const PgResult r = query("SELECT least(greatest(floor((t - $3::float8) / $5::float8 * $6::int)::int, 0), $6::int - 1) AS b, min(t), max(t), min(" + d +
                               "), max(" + d + "), min(" + f + "), max(" + f + "), count(*) FROM " + table +
                               " WHERE daemon_id = $1 AND run_id = $2 AND t BETWEEN $3::float8 AND $4::float8 GROUP BY b ORDER BY b",
                           {std::to_string(run_id), exact(t0), exact(t1), exact(span), std::to_string(n)});
  std::vector<Bucket> out;
  for (int k = 0; k < r.rows(); ++k)
    out.push_back({pg_num(r, k, 1), pg_num(r, k, 2), pg_num(r, k, 3), pg_num(r, k, 4), pg_num(r, k, 5), pg_num(r, k, 6), r.integer(k, 7)});
  return out;
}

void PgReads::for_each_sample(std::int64_t run_id, std::int64_t seq0, std::int64_t seq1, const std::function<void(const SampleRow&)>& f) {
  const std::string u = std::to_string(run_id);
  chunked(
      [&](const std::string& from, const std::string& to) {
        return query(
            "SELECT seq, t, coalesce(cmd, 0), coalesce(disp, 0), coalesce(force, 0), coalesce(status, 0) FROM hystlab.samples "
            "WHERE daemon_id = $1 AND run_id = $2 AND seq BETWEEN $3 AND $4 ORDER BY seq LIMIT 50000",
            {u, from, to});
      },
      seq0, seq1,
      [&](const PgResult& r, int k) {
        f(SampleRow{run_id, r.integer(k, 0), pg_num(r, k, 1), pg_num(r, k, 2), pg_num(r, k, 3), pg_num(r, k, 4), r.integer(k, 5)});
      });
}

void PgReads::for_each_shaker_sample(std::int64_t run_id, std::int64_t seq0, std::int64_t seq1, const std::function<void(const ShakerRow&)>& f) {
  std::string cols = "seq, t";
  for (const char* c : kShakerValues) cols += ", coalesce(" + std::string(c) + ", 0)";
  const std::string u = std::to_string(run_id);
  chunked(
      [&](const std::string& from, const std::string& to) {
        return query("SELECT " + cols +
                         ", coalesce(status, 0) FROM hystlab.shaker_samples WHERE daemon_id = $1 AND run_id = $2 AND seq BETWEEN $3 AND $4 "
                         "ORDER BY seq LIMIT 50000",
                     {u, from, to});
      },
      seq0, seq1,
      [&](const PgResult& r, int k) {
        std::array<double, 6> v{};
        for (std::size_t c = 0; c < v.size(); ++c) v[c] = pg_num(r, k, static_cast<int>(c) + 2);
        f(ShakerRow{run_id, r.integer(k, 0), pg_num(r, k, 1), domain::shaker_sample(v), r.integer(k, 8)});
      });
}

std::int64_t PgReads::read_xy(std::int64_t run_id, std::int64_t seq0, bool base_mass, std::vector<float>& x, std::vector<float>& y) {
  std::int64_t next = seq0;
  const auto last = std::numeric_limits<std::int64_t>::max();
  if (base_mass)
    for_each_shaker_sample(run_id, seq0, last, [&](const ShakerRow& r) {
      x.push_back(static_cast<float>(r.v.base_displacement_mm));
      y.push_back(static_cast<float>(r.v.mass_displacement_mm));
      next = r.seq + 1;
    });
  else
    for_each_sample(run_id, seq0, last, [&](const SampleRow& r) {
      x.push_back(static_cast<float>(r.disp));
      y.push_back(static_cast<float>(r.force));
      next = r.seq + 1;
    });
  return next;
}

std::int64_t PgReads::table_count(std::int64_t campaign_id) {
  return query("SELECT count(*) FROM hystlab.tables WHERE daemon_id = $1 AND campaign_id = $2", {std::to_string(campaign_id)}).integer(0, 0);
}

std::vector<TableInfo> PgReads::tables_where(const std::string& where, const std::vector<std::string>& more) {
  const PgResult r = query(kTableSelect + where, more);
  std::vector<TableInfo> out;
  for (int k = 0; k < r.rows(); ++k) {
    TableInfo t;
    t.id = r.integer(k, 0);
    if (!r.is_null(k, 1)) t.campaign = r.integer(k, 1);
    if (!r.is_null(k, 2)) t.run = r.integer(k, 2);
    t.method = r.text(k, 3), t.n = r.integer(k, 4), t.range_lo = pg_num(r, k, 5), t.range_hi = pg_num(r, k, 6), t.created_at = r.text(k, 7);
    t.accuracy_json = r.text(k, 8);
    out.push_back(std::move(t));
  }
  return out;
}

std::vector<TableInfo> PgReads::tables(std::optional<std::int64_t> campaign_id) {
  if (campaign_id) return tables_where("AND campaign_id = $2 ORDER BY id", {std::to_string(*campaign_id)});
  return tables_where("ORDER BY id", {});
}

std::optional<TableInfo> PgReads::table(std::int64_t id) {
  auto found = tables_where("AND id = $2", {std::to_string(id)});
  if (found.empty()) return std::nullopt;
  return std::move(found.front());
}

std::optional<std::string> PgReads::table_document(std::int64_t id) {
  const PgResult r = query("SELECT coalesce(document::text, '') FROM hystlab.tables WHERE daemon_id = $1 AND id = $2", {std::to_string(id)});
  if (r.rows() == 0) return std::nullopt;
  return r.text(0, 0);
}

std::optional<TableInfo> PgReads::newest_table_of_rig(std::int64_t rig_id, const std::string& method) {
  auto found =
      tables_where("AND method = $2 AND campaign_id IN (SELECT id FROM hystlab.campaigns WHERE daemon_id = $1 AND rig_id = $3) ORDER BY id DESC LIMIT 1",
                   {method, std::to_string(rig_id)});
  if (found.empty()) return std::nullopt;
  return std::move(found.front());
}

std::optional<TableInfo> PgReads::newest_table_of_campaign(std::int64_t campaign_id, const std::string& method) {
  auto found = tables_where("AND method = $2 AND campaign_id = $3 ORDER BY id DESC LIMIT 1", {method, std::to_string(campaign_id)});
  if (found.empty()) return std::nullopt;
  return std::move(found.front());
}

std::vector<NodeInfo> PgReads::nodes(std::int64_t campaign_id) {
  const PgResult r = query(kNodeSelect + "AND u.campaign_id = $2 ORDER BY f.id", {std::to_string(campaign_id)});
  std::vector<NodeInfo> out;
  for (int k = 0; k < r.rows(); ++k)
    out.push_back({r.integer(k, 0), r.integer(k, 1), pg_opt_int(r, k, 2), pg_num(r, k, 3), pg_num(r, k, 4), pg_num(r, k, 5), pg_num(r, k, 6), pg_num(r, k, 7)});
  return out;
}

std::vector<std::tuple<double, double, double, double>> PgReads::fot_nodes_of_campaign(std::int64_t campaign_id) {
  std::vector<std::tuple<double, double, double, double>> out;
  for (const NodeInfo& n : nodes(campaign_id)) out.emplace_back(n.alpha, n.beta, n.force_alpha, n.force_alpha_beta);
  return out;
}

std::vector<TransmissibilityInfo> PgReads::transmissibility(std::int64_t campaign_id) {
  const PgResult r = query(
      "SELECT t.id, t.run_id, coalesce(frequency_hz, 0), coalesce(base_amplitude_mm, 0), coalesce(mass_amplitude_mm, 0), coalesce(ratio, 0), "
      "coalesce(phase_rad, 0), coalesce(step, 0), coalesce(demand_mm, 0), coalesce(direction, ''), coalesce(detail, ''), predicted_ratio, "
      "predicted_phase_rad FROM hystlab.transmissibility t JOIN hystlab.runs u ON u.daemon_id = t.daemon_id AND u.id = t.run_id "
      "WHERE t.daemon_id = $1 AND u.campaign_id = $2 ORDER BY t.id",
      {std::to_string(campaign_id)});
  std::vector<TransmissibilityInfo> out;
  for (int k = 0; k < r.rows(); ++k) {
    TransmissibilityInfo t{r.integer(k, 0), pg_opt_int(r, k, 1), pg_num(r, k, 2), pg_num(r, k, 3), pg_num(r, k, 4), pg_num(r, k, 5),
                           pg_num(r, k, 6), r.integer(k, 7),     pg_num(r, k, 8), r.text(k, 9),    r.text(k, 10)};
    if (!r.is_null(k, 11)) t.predicted_ratio = pg_num(r, k, 11), t.predicted_phase_rad = pg_num(r, k, 12);
    out.push_back(std::move(t));
  }
  return out;
}

std::vector<LoopInfo> PgReads::loops(std::int64_t campaign_id) {
  const PgResult r = query(
      "SELECT l.run_id, l.k, coalesce(l.phase, ''), coalesce(l.figures::text, '{}') FROM hystlab.loops l JOIN hystlab.runs u ON u.daemon_id = l.daemon_id "
      "AND u.id = l.run_id WHERE l.daemon_id = $1 AND u.campaign_id = $2 ORDER BY l.run_id, l.k",
      {std::to_string(campaign_id)});
  std::vector<LoopInfo> out;
  for (int k = 0; k < r.rows(); ++k) out.push_back({r.integer(k, 0), r.integer(k, 1), r.text(k, 2), r.text(k, 3)});
  return out;
}

}  // namespace hystlab::db
