#include "hystlab/db/lab_reads.hpp"

#include "pg_values.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <iterator>

namespace hystlab::db {
namespace {

constexpr const char* kFrameColumns[] = {"t", "cmd", "disp", "force"};
constexpr const char* kShakerColumns[] = {
    "t", "drive_frequency_hz", "drive_amplitude_mm", "base_displacement_mm", "mass_displacement_mm", "base_accel_m_s2", "mass_accel_m_s2"};
std::vector<std::string> columns_of(bool shaker) {
  return shaker ? std::vector<std::string>(std::begin(kShakerColumns), std::end(kShakerColumns))
                : std::vector<std::string>(std::begin(kFrameColumns), std::end(kFrameColumns));
}
std::string joined(const std::vector<std::string>& cols, const std::string& before = "", const std::string& after = "") {
  std::string s;
  for (const std::string& c : cols) s += (s.empty() ? "" : ", ") + before + c + after;
  return s;
}
// $k placeholders for the filter's non-empty fields, appended to sql's WHERE.
std::string filtered(std::string sql, const LabFilter& f, std::vector<const char*>& params) {
  const std::pair<const char*, const std::string*> fields[] = {{"lab", &f.lab}, {"daemon", &f.daemon}, {"specimen", &f.specimen}, {"kind", &f.kind}};
  bool first = true;
  for (const auto& [col, value] : fields) {
    if (value->empty()) continue;
    params.push_back(value->c_str());
    sql += std::string(first ? " WHERE " : " AND ") + col + " = $" + std::to_string(params.size());
    first = false;
  }
  return sql;
}
}  // namespace

std::vector<LabDaemon> LabReads::daemons(const std::string& lab) {
  const PgResult r = pg_.query(
      "SELECT id, lab, name, coalesce(software, ''), first_seen::text, last_seen::text, coalesce(url, '') FROM hystlab.daemons "
      "WHERE $1 = '' OR lab = $1 ORDER BY lab, name",
      {lab.c_str()});
  std::vector<LabDaemon> out;
  for (int k = 0; k < r.rows(); ++k)
    out.push_back({static_cast<int>(r.integer(k, 0)), r.text(k, 1), r.text(k, 2), r.text(k, 3), r.text(k, 4), r.text(k, 5), r.text(k, 6)});
  return out;
}

std::vector<LabRig> LabReads::rigs(const std::string& lab) {
  const PgResult r = pg_.query(
      "SELECT daemon_id, daemon, rig, rig_id, last_campaign, last_campaign_state FROM hystlab.lab_rigs "
      "WHERE $1 = '' OR lab = $1 ORDER BY daemon, rig",
      {lab.c_str()});
  std::vector<LabRig> out;
  for (int k = 0; k < r.rows(); ++k) {
    LabRig g;
    g.daemon_id = static_cast<int>(r.integer(k, 0)), g.daemon = r.text(k, 1), g.name = r.text(k, 2), g.id = r.integer(k, 3);
    g.last_campaign = pg_opt_int(r, k, 4), g.last_campaign_state = pg_opt(r, k, 5);
    out.push_back(std::move(g));
  }
  return out;
}

std::vector<LabCampaign> LabReads::campaigns(const LabFilter& f) {
  std::vector<const char*> params;
  const std::string limit = std::to_string(f.limit > 0 ? f.limit : 200);
  const PgResult r = pg_.query(filtered("SELECT daemon_id, lab, daemon, coalesce(rig, ''), campaign, kind, state, coalesce(specimen, ''), "
                                        "created_at::text, updated_at::text FROM hystlab.lab_campaigns",
                                        f, params) +
                                   " ORDER BY updated_at DESC, daemon, campaign DESC LIMIT " + limit,
                               params);
  std::vector<LabCampaign> out;
  for (int k = 0; k < r.rows(); ++k) {
    LabCampaign c;
    c.daemon_id = static_cast<int>(r.integer(k, 0)), c.lab = r.text(k, 1), c.daemon = r.text(k, 2), c.rig = r.text(k, 3);
    c.id = r.integer(k, 4), c.kind = pg_opt(r, k, 5), c.state = pg_opt(r, k, 6), c.specimen = r.text(k, 7);
    c.created_at = pg_opt(r, k, 8), c.updated_at = pg_opt(r, k, 9);
    out.push_back(std::move(c));
  }
  return out;
}

std::optional<LabCampaign> LabReads::campaign(const std::string& daemon, std::int64_t id, const std::string& lab) {
  const std::string ids = std::to_string(id);
  const PgResult r = pg_.query(
      "SELECT v.daemon_id, v.lab, v.daemon, coalesce(v.rig, ''), v.campaign, v.kind, v.state, coalesce(v.specimen, ''), v.created_at::text, "
      "v.updated_at::text, c.plan::text FROM hystlab.lab_campaigns v JOIN hystlab.campaigns c ON c.daemon_id = v.daemon_id AND c.id = v.campaign "
      "WHERE v.daemon = $1 AND v.campaign = $2 AND ($3 = '' OR v.lab = $3)",
      {daemon.c_str(), ids.c_str(), lab.c_str()});
  if (r.rows() == 0) return std::nullopt;
  LabCampaign c;
  c.daemon_id = static_cast<int>(r.integer(0, 0)), c.lab = r.text(0, 1), c.daemon = r.text(0, 2), c.rig = r.text(0, 3);
  c.id = r.integer(0, 4), c.kind = pg_opt(r, 0, 5), c.state = pg_opt(r, 0, 6), c.specimen = r.text(0, 7);
  c.created_at = pg_opt(r, 0, 8), c.updated_at = pg_opt(r, 0, 9), c.plan = pg_opt(r, 0, 10);
  return c;
}

namespace {
// The runs of a daemon that match `where` ($1 the daemon, $2 the campaign or the run).
std::vector<LabRun> runs_where(PgConnection& pg, const std::string& where, int daemon_id, std::int64_t key) {
  const std::string d = std::to_string(daemon_id), c = std::to_string(key);
  const PgResult r = pg.query(
      "SELECT u.id, coalesce(u.role, ''), coalesce(u.state, ''), coalesce(u.started_at::text, ''), coalesce(u.ended_at::text, ''), "
      "coalesce(m.mark + 1, 0), m.tbl = 'shaker_samples', coalesce(u.campaign_id, 0) FROM hystlab.runs u LEFT JOIN hystlab.marks m "
      "ON m.daemon_id = u.daemon_id AND m.tbl IN ('samples', 'shaker_samples') AND m.key = u.id WHERE u.daemon_id = $1 AND " +
          where + " ORDER BY u.id",
      {d.c_str(), c.c_str()});
  std::vector<LabRun> out;
  for (int k = 0; k < r.rows(); ++k)
    out.push_back({r.integer(k, 0), r.integer(k, 5), r.text(k, 1), r.text(k, 2), r.text(k, 3), r.text(k, 4), pg_opt(r, k, 6) == "t", r.integer(k, 7)});
  return out;
}
}  // namespace

std::vector<LabRun> LabReads::runs(int daemon_id, std::int64_t campaign) { return runs_where(pg_, "u.campaign_id = $2", daemon_id, campaign); }

std::optional<LabRun> LabReads::run(int daemon_id, std::int64_t id) {
  auto found = runs_where(pg_, "u.id = $2", daemon_id, id);
  if (found.empty()) return std::nullopt;
  return std::move(found.front());
}

std::vector<LabEvent> LabReads::events(int daemon_id, std::int64_t campaign, int limit) {
  const std::string d = std::to_string(daemon_id), c = std::to_string(campaign), l = std::to_string(limit);
  const PgResult r = pg_.query(
      "SELECT id, coalesce(at::text, ''), coalesce(kind, ''), coalesce(from_state, ''), coalesce(to_state, ''), coalesce(detail, '') "
      "FROM hystlab.events WHERE daemon_id = $1 AND campaign_id = $2 ORDER BY id LIMIT $3",
      {d.c_str(), c.c_str(), l.c_str()});
  std::vector<LabEvent> out;
  for (int k = 0; k < r.rows(); ++k) out.push_back({r.integer(k, 0), r.text(k, 1), r.text(k, 2), r.text(k, 3), r.text(k, 4), r.text(k, 5)});
  return out;
}

namespace {
constexpr const char* kTableColumns =
    "SELECT daemon_id, daemon, coalesce(specimen, ''), coalesce(method, ''), coalesce(created_at::text, ''), coalesce(accuracy, ''), table_id, "
    "coalesce(campaign, 0), coalesce(n, 0), range_lo, range_hi FROM hystlab.lab_tables";
std::vector<LabTable> tables_in(const PgResult& r) {
  std::vector<LabTable> out;
  for (int k = 0; k < r.rows(); ++k) {
    LabTable t;
    t.daemon_id = static_cast<int>(r.integer(k, 0)), t.daemon = r.text(k, 1), t.specimen = r.text(k, 2), t.method = r.text(k, 3);
    t.created_at = r.text(k, 4), t.accuracy = r.text(k, 5), t.id = r.integer(k, 6), t.campaign = r.integer(k, 7);
    t.n = static_cast<int>(r.integer(k, 8)), t.range_lo = pg_num(r, k, 9), t.range_hi = pg_num(r, k, 10);
    out.push_back(std::move(t));
  }
  return out;
}
}  // namespace

std::vector<LabTable> LabReads::tables(const LabFilter& f) {
  std::vector<const char*> params;
  const std::string limit = std::to_string(f.limit > 0 ? f.limit : 200);
  return tables_in(pg_.query(
      filtered(kTableColumns, LabFilter{f.lab, f.daemon, f.specimen, {}, f.limit}, params) + " ORDER BY specimen, created_at LIMIT " + limit, params));
}

std::vector<LabTable> LabReads::campaign_tables(int daemon_id, std::int64_t campaign) {
  const std::string d = std::to_string(daemon_id), c = std::to_string(campaign);
  return tables_in(pg_.query(std::string(kTableColumns) + " WHERE daemon_id = $1 AND campaign = $2 ORDER BY table_id", {d.c_str(), c.c_str()}));
}

std::optional<std::string> LabReads::table_document(const std::string& daemon, std::int64_t id) {
  const std::string ids = std::to_string(id);
  const PgResult r = pg_.query("SELECT t.document::text FROM hystlab.tables t JOIN hystlab.daemons d ON d.id = t.daemon_id WHERE d.name = $1 AND t.id = $2",
                               {daemon.c_str(), ids.c_str()});
  if (r.rows() == 0 || r.is_null(0, 0)) return std::nullopt;
  return r.text(0, 0);
}

LabOverview LabReads::overview(int daemon_id, std::int64_t run, bool shaker, int buckets) {
  LabOverview o;
  o.columns = columns_of(shaker);
  const std::string d = std::to_string(daemon_id), u = std::to_string(run), table = shaker ? "hystlab.shaker_samples" : "hystlab.samples";
  const PgResult n = pg_.query("SELECT coalesce(max(seq), -1) + 1 FROM " + table + " WHERE daemon_id = $1 AND run_id = $2", {d.c_str(), u.c_str()});
  const std::int64_t count = n.integer(0, 0);
  o.min.assign(o.columns.size(), {});
  o.max.assign(o.columns.size(), {});
  if (count == 0) return o;
  const std::int64_t width = std::max<std::int64_t>(1, (count + buckets - 1) / std::max(1, buckets));
  const std::string w = std::to_string(width);
  const PgResult r = pg_.query("SELECT seq / " + w + " AS b, " + joined(o.columns, "min(", ")") + ", " + joined(o.columns, "max(", ")") + " FROM " + table +
                                   " WHERE daemon_id = $1 AND run_id = $2 GROUP BY b ORDER BY b",
                               {d.c_str(), u.c_str()});
  const int nc = static_cast<int>(o.columns.size());
  for (int k = 0; k < r.rows(); ++k)
    for (int c = 0; c < nc; ++c) {
      o.min[static_cast<std::size_t>(c)].push_back(pg_num(r, k, 1 + c));
      o.max[static_cast<std::size_t>(c)].push_back(pg_num(r, k, 1 + nc + c));
    }
  return o;
}

}  // namespace hystlab::db
