#include "hystlab/db/store.hpp"

#include <atomic>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "hystlab/db/schema.hpp"
#include "hystlab/domain/signals.hpp"

namespace hystlab::db {
namespace {
std::atomic<std::uint64_t> g_records{0};
}  // namespace
void records_changed() noexcept { g_records.fetch_add(1, std::memory_order_release); }

std::uint64_t record_generation() noexcept { return g_records.load(std::memory_order_acquire); }
namespace {
struct BlockDelta {
  std::int64_t n = 0;
  double t_min = std::numeric_limits<double>::infinity(), t_max = -t_min, d_min = t_min, d_max = -t_min, f_min = t_min, f_max = -t_min;
  void add(double t, double d, double f) {
    ++n;
    t_min = std::min(t_min, t), t_max = std::max(t_max, t);
    d_min = std::min(d_min, d), d_max = std::max(d_max, d);
    f_min = std::min(f_min, f), f_max = std::max(f_max, f);
  }
};

void merge(Bucket& b, double t0, double t1, double d0, double d1, double f0, double f1, std::int64_t n) {
  if (b.n == 0) b = Bucket{t0, t1, d0, d1, f0, f1, 0};
  b.t_min = std::min(b.t_min, t0), b.t_max = std::max(b.t_max, t1);
  b.disp_min = std::min(b.disp_min, d0), b.disp_max = std::max(b.disp_max, d1);
  b.force_min = std::min(b.force_min, f0), b.force_max = std::max(b.force_max, f1);
  b.n += n;
}
}  // namespace

detail::OpenDatabase::OpenDatabase(const std::string& path, bool synchronous_full) : db(path, synchronous_full) { migrate(db); }

Store::Store(const std::string& path, bool synchronous_full)
    : OpenDatabase(path, synchronous_full), Reads(OpenDatabase::db), Writes(OpenDatabase::db), Lifecycle(OpenDatabase::db, *this) {}

Writes::Writes(Database& db)
    : db_(db),
      insert_sample_(db_, "INSERT INTO samples(run_id, seq, t, cmd, disp, force, status) VALUES(?,?,?,?,?,?,?)"),
      upsert_block_(db_,
                    "INSERT INTO sample_blocks(run_id, block, n, t_min, t_max, disp_min, disp_max, force_min, force_max) "
                    "VALUES(?,?,?,?,?,?,?,?,?) ON CONFLICT(run_id, block) DO UPDATE SET n = n + excluded.n, "
                    "t_min = min(t_min, excluded.t_min), t_max = max(t_max, excluded.t_max), "
                    "disp_min = min(disp_min, excluded.disp_min), disp_max = max(disp_max, excluded.disp_max), "
                    "force_min = min(force_min, excluded.force_min), force_max = max(force_max, excluded.force_max)"),
      insert_shaker_(db_,
                     "INSERT INTO shaker_samples(run_id, seq, t, drive_frequency_hz, drive_amplitude_mm, base_displacement_mm, "
                     "mass_displacement_mm, base_accel_m_s2, mass_accel_m_s2, status) VALUES(?,?,?,?,?,?,?,?,?,?)") {}

std::int64_t Lifecycle::upsert_rig(const std::string& name, const std::string& config, const std::string& now) {
  Statement st(db_,
               "INSERT INTO rigs(name, config, created_at) VALUES(?,?,?) "
               "ON CONFLICT(name) DO UPDATE SET config = excluded.config RETURNING id");
  st.bind(1, name).bind(2, config).bind(3, now);
  st.step();
  return st.column_int(0);
}

std::int64_t Lifecycle::create_campaign(std::int64_t rig, domain::CampaignKind kind, const std::string& plan, const std::string& now) {
  Transaction tx(db_);
  Statement st(db_, "INSERT INTO campaigns(rig_id, kind, plan, state, created_at, updated_at) VALUES(?,?,?,'queued',?,?)");
  st.bind(1, rig).bind(2, std::string_view(to_string(kind))).bind(3, plan).bind(4, now).bind(5, now);
  st.step();
  const std::int64_t id = db_.last_insert_rowid();
  Statement ev(db_, "INSERT INTO events(campaign_id, at, kind, to_state, detail) VALUES(?,?,'state',?,'submitted')");
  ev.bind(1, id).bind(2, now).bind(3, std::string_view("queued"));
  ev.step();
  tx.commit();
  records_changed();
  return id;
}

void Lifecycle::transition(std::int64_t id, domain::CampaignState to, const std::string& reason, const std::string& now) {
  Transaction tx(db_);
  transition_in(id, to, reason, now);
  tx.commit();
  records_changed();
}

void Lifecycle::transition_in(std::int64_t id, domain::CampaignState to, const std::string& reason, const std::string& now) {
  Statement cur(db_, "SELECT state FROM campaigns WHERE id = ?");
  cur.bind(1, id);
  if (!cur.step()) throw DbError("no campaign " + std::to_string(id), 0);
  const std::string from = cur.column_text(0);
  Statement up(db_, "UPDATE campaigns SET state = ?, updated_at = ? WHERE id = ?");
  up.bind(1, std::string_view(to_string(to))).bind(2, now).bind(3, id);
  up.step();
  Statement ev(db_, "INSERT INTO events(campaign_id, at, kind, from_state, to_state, detail) VALUES(?,?,'state',?,?,?)");
  ev.bind(1, id).bind(2, now).bind(3, from).bind(4, std::string_view(to_string(to))).bind(5, reason);
  ev.step();
}

std::int64_t Lifecycle::add_run(std::int64_t campaign, const std::string& now, double wall, double mono, domain::RunRole role) {
  Statement st(db_, "INSERT INTO runs(campaign_id, started_at, wall_anchor_unix, monotonic_anchor_s, state, role) VALUES(?,?,?,?,'running',?)");
  st.bind(1, campaign).bind(2, now).bind(3, wall).bind(4, mono).bind(5, std::string_view(to_string(role)));
  st.step();
  return db_.last_insert_rowid();
}

std::pair<std::int64_t, std::int64_t> Lifecycle::add_runs(std::int64_t campaign, const std::string& now, double wall, double mono, bool validation) {
  Transaction tx(db_);
  const std::int64_t run = add_run(campaign, now, wall, mono);
  const std::int64_t vrun = validation ? add_run(campaign, now, wall, mono, domain::RunRole::validation) : 0;
  tx.commit();
  return {run, vrun};
}

void Lifecycle::end_run(std::int64_t run, domain::CampaignState state, const std::string& now) {
  Statement st(db_, "UPDATE runs SET state = ?, ended_at = ? WHERE id = ?");
  st.bind(1, std::string_view(to_string(state))).bind(2, now).bind(3, run);
  st.step();
}

std::int64_t Lifecycle::add_event(std::int64_t campaign, const domain::CampaignEvent& event, const std::string& now) {
  return add_raw_event(campaign, std::string(domain::kind_of(event)), domain::encode(event), now);
}

std::int64_t Lifecycle::add_raw_event(std::int64_t campaign, const std::string& kind, const std::string& detail, const std::string& now) {
  Statement st(db_, "INSERT INTO events(campaign_id, at, kind, detail) VALUES(?,?,?,?)");
  st.bind(1, campaign).bind(2, now).bind(3, kind).bind(4, detail);
  st.step();
  records_changed();
  return db_.last_insert_rowid();
}

std::int64_t Writes::add_transmissibility(std::int64_t run, double f, double base, double mass, double ratio, double phase) {
  Statement st(db_,
               "INSERT INTO transmissibility(run_id, frequency_hz, base_amplitude_mm, mass_amplitude_mm, ratio, phase_rad) "
               "VALUES(?,?,?,?,?,?)");
  st.bind(1, run).bind(2, f).bind(3, base).bind(4, mass).bind(5, ratio).bind(6, phase);
  st.step();
  records_changed();
  return db_.last_insert_rowid();
}

std::int64_t Writes::add_sine_point(std::int64_t run, const SinePointRow& p) {
  Statement st(db_,
               "INSERT INTO transmissibility(run_id, frequency_hz, base_amplitude_mm, mass_amplitude_mm, ratio, phase_rad, step, demand_mm, "
               "direction, detail) VALUES(?,?,?,?,?,?,?,?,?,?)");
  st.bind(1, run).bind(2, p.frequency_hz).bind(3, p.base_amplitude_mm).bind(4, p.mass_amplitude_mm).bind(5, p.ratio).bind(6, p.phase_rad);
  st.bind(7, p.step).bind(8, p.demand_mm).bind(9, p.direction).bind(10, p.detail);
  st.step();
  records_changed();
  return db_.last_insert_rowid();
}

void Writes::set_prediction(std::int64_t point, double ratio, double phase) {
  Statement st(db_, "UPDATE transmissibility SET predicted_ratio = ?, predicted_phase_rad = ? WHERE id = ?");
  st.bind(1, ratio).bind(2, phase).bind(3, point);
  st.step();
  records_changed();
}

std::int64_t Writes::add_fot_node(std::int64_t run, double a, double b, double fa, double fab, double t) {
  Statement st(db_, "INSERT INTO fot_nodes(run_id, alpha, beta, force_alpha, force_alpha_beta, t) VALUES(?,?,?,?,?,?)");
  st.bind(1, run).bind(2, a).bind(3, b).bind(4, fa).bind(5, fab).bind(6, t);
  st.step();
  records_changed();
  return db_.last_insert_rowid();
}

std::int64_t Lifecycle::add_table(std::optional<std::int64_t> campaign, std::optional<std::int64_t> run, const std::string& method, int n, double lo, double hi,
                                  const std::string& now, const std::string& accuracy, const std::string& document) {
  Statement st(db_,
               "INSERT INTO tables(campaign_id, run_id, method, n, range_lo, range_hi, created_at, accuracy, document) "
               "VALUES(?,?,?,?,?,?,?,?,?)");
  campaign ? st.bind(1, *campaign) : st.bind_null(1);
  run ? st.bind(2, *run) : st.bind_null(2);
  st.bind(3, method).bind(4, n).bind(5, lo).bind(6, hi).bind(7, now).bind(8, accuracy).bind(9, document);
  st.step();
  records_changed();
  return db_.last_insert_rowid();
}

int Lifecycle::mark_interrupted(const std::string& now) {
  std::vector<std::int64_t> ids;
  {
    Statement st(db_, "SELECT id FROM campaigns WHERE state IN ('arming', 'running', 'paused')");
    while (st.step()) ids.push_back(st.column_int(0));
  }
  for (auto id : ids)
    if (reads_.table_count(id) > 0)
      transition(id, domain::CampaignState::completed, "its tables were stored before the daemon stopped", now);
    else
      transition(id, domain::CampaignState::interrupted, "the daemon stopped without finishing it", now);
  Statement runs(db_, "UPDATE runs SET state = 'interrupted', ended_at = ? WHERE state = 'running'");
  runs.bind(1, now);
  runs.step();
  return static_cast<int>(ids.size());
}

std::vector<std::int64_t> Reads::queued_campaigns(std::int64_t rig) {
  std::vector<std::int64_t> out;
  Statement st(db_, "SELECT id FROM campaigns WHERE rig_id = ? AND state = 'queued' ORDER BY id");
  st.bind(1, rig);
  while (st.step()) out.push_back(st.column_int(0));
  return out;
}

std::vector<std::tuple<double, double, double, double>> Reads::fot_nodes_of_campaign(std::int64_t campaign) {
  std::vector<std::tuple<double, double, double, double>> out;
  Statement st(db_,
               "SELECT alpha, beta, force_alpha, force_alpha_beta FROM fot_nodes JOIN runs ON runs.id = fot_nodes.run_id "
               "WHERE runs.campaign_id = ? ORDER BY fot_nodes.id");
  st.bind(1, campaign);
  while (st.step()) out.emplace_back(st.column_double(0), st.column_double(1), st.column_double(2), st.column_double(3));
  return out;
}

namespace {
using Blocks = std::map<std::pair<std::int64_t, std::int64_t>, BlockDelta>;
}

void Writes::insert_samples(std::span<const SampleRow> rows) {
  std::vector<AnyRow> all(rows.begin(), rows.end());
  insert_rows(all);
}

void Writes::insert_rows(std::span<const AnyRow> rows) {
  Blocks blocks;
  for (const AnyRow& any : rows) {
    if (const auto* r = std::get_if<SampleRow>(&any)) {
      insert_sample_.reset();
      insert_sample_.bind(1, r->run_id).bind(2, r->seq).bind(3, r->t).bind(4, r->cmd).bind(5, r->disp).bind(6, r->force).bind(7, r->status);
      insert_sample_.step();
      blocks[{r->run_id, r->seq / kBlockSize}].add(r->t, r->disp, r->force);
      continue;
    }
    const ShakerRow& r = std::get<ShakerRow>(any);
    insert_shaker_.reset();
    insert_shaker_.bind(1, r.run_id).bind(2, r.seq).bind(3, r.t);
    const auto v = domain::values(r.v);  // the columns are kShakerSignals' names, in order
    for (std::size_t k = 0; k < v.size(); ++k) insert_shaker_.bind(static_cast<int>(k) + 4, v[k]);
    insert_shaker_.bind(10, r.status);
    insert_shaker_.step();
    blocks[{r.run_id, r.seq / kBlockSize}].add(r.t, r.v.base_displacement_mm, r.v.mass_displacement_mm);
  }
  for (const auto& [key, b] : blocks) {
    upsert_block_.reset();
    upsert_block_.bind(1, key.first).bind(2, key.second).bind(3, b.n).bind(4, b.t_min).bind(5, b.t_max);
    upsert_block_.bind(6, b.d_min).bind(7, b.d_max).bind(8, b.f_min).bind(9, b.f_max);
    upsert_block_.step();
  }
}

namespace {
// The text columns back to enums: a value this program never wrote is named, not guessed.
CampaignRow campaign_row(Statement& st) {
  CampaignRow r;
  r.id = st.column_int(0);
  r.rig_id = st.column_int(1);
  const std::string kind = st.column_text(2), state = st.column_text(4);
  const auto k = domain::campaign_kind_from(kind);
  const auto s = domain::campaign_state_from(state);
  if (!k) throw DbError("campaign " + std::to_string(r.id) + ": unknown kind '" + kind + "' in the database", 0);
  if (!s) throw DbError("campaign " + std::to_string(r.id) + ": unknown state '" + state + "' in the database", 0);
  r.kind = *k;
  r.plan = st.column_text(3);
  r.state = *s;
  r.created_at = st.column_text(5);
  r.updated_at = st.column_text(6);
  return r;
}
}  // namespace

std::optional<CampaignRow> Reads::campaign(std::int64_t id) {
  Statement st(db_, "SELECT id, rig_id, kind, plan, state, created_at, updated_at FROM campaigns WHERE id = ?");
  st.bind(1, id);
  if (!st.step()) return std::nullopt;
  return campaign_row(st);
}

std::vector<CampaignRow> Reads::campaigns() {
  std::vector<CampaignRow> out;
  Statement st(db_, "SELECT id, rig_id, kind, plan, state, created_at, updated_at FROM campaigns ORDER BY id");
  while (st.step()) out.push_back(campaign_row(st));
  return out;
}

std::vector<EventRow> Reads::events(std::int64_t campaign) {
  std::vector<EventRow> out;
  Statement st(db_, "SELECT id, at, kind, from_state, to_state, detail FROM events WHERE campaign_id = ? ORDER BY id");
  st.bind(1, campaign);
  while (st.step()) out.push_back({st.column_int(0), st.column_text(1), st.column_text(2), st.column_text(3), st.column_text(4), st.column_text(5)});
  return out;
}

std::int64_t Reads::sample_count(std::int64_t run) {
  Statement st(db_, "SELECT coalesce(sum(n), 0) FROM sample_blocks WHERE run_id = ?");
  st.bind(1, run);
  st.step();
  return st.column_int(0);
}

std::int64_t Reads::max_seq(std::int64_t run) {
  Statement st(db_, "SELECT coalesce(max(seq), -1) FROM samples WHERE run_id = ?");
  st.bind(1, run);
  st.step();
  return st.column_int(0);
}

// Raw rows an overview reads at most (about 0.2 s here); beyond, block summaries.
constexpr std::int64_t kRawOverviewRows = 200'000;

std::vector<Bucket> Reads::overview(std::int64_t run, double t0, double t1, int buckets, bool shaker) {
  std::vector<Bucket> out(static_cast<std::size_t>(std::max(1, buckets)));
  const double span = t1 > t0 ? t1 - t0 : 1.0;
  auto slot = [&](double t) {
    const auto k = static_cast<long>((t - t0) / span * static_cast<double>(out.size()));
    return static_cast<std::size_t>(std::clamp<long>(k, 0, static_cast<long>(out.size()) - 1));
  };
  Statement blocks(db_,
                   "SELECT block, n, t_min, t_max, disp_min, disp_max, force_min, force_max FROM sample_blocks "
                   "WHERE run_id = ? AND t_max >= ? AND t_min <= ? ORDER BY block");
  blocks.bind(1, run).bind(2, t0).bind(3, t1);
  std::int64_t first = -1, last = -1, total = 0;
  std::vector<Bucket> from_blocks(out.size());
  while (blocks.step()) {
    const std::int64_t b = blocks.column_int(0);
    if (first < 0) first = b;
    last = b;
    total += blocks.column_int(1);
    const double tm = 0.5 * (blocks.column_double(2) + blocks.column_double(3));
    merge(from_blocks[slot(tm)], blocks.column_double(2), blocks.column_double(3), blocks.column_double(4), blocks.column_double(5), blocks.column_double(6),
          blocks.column_double(7), blocks.column_int(1));
  }
  if (first < 0) return {};
  const std::int64_t nblocks = last - first + 1;
  // At least two blocks per bucket, or too many raw rows to read: the block summaries answer
  // (each keeps its min and max, so no peak is lost; only the time resolution is the block's).
  // The limit was 2,000,000 rows: a completed 10^6-sample run's 3,000-point overview then read
  // every row, 4-11 s of the page's first render on these machines (stop 20's bench_page).
  if (nblocks >= 2 * static_cast<std::int64_t>(out.size()) || total > kRawOverviewRows) {
    std::erase_if(from_blocks, [](const Bucket& b) { return b.n == 0; });
    return from_blocks;
  }
  auto take = [&](double t, double d, double f) {
    if (t >= t0 && t <= t1) merge(out[slot(t)], t, t, d, d, f, f, 1);
  };
  if (shaker)
    for_each_shaker_sample(run, first * kBlockSize, (last + 1) * kBlockSize - 1,
                           [&](const ShakerRow& r) { take(r.t, r.v.base_displacement_mm, r.v.mass_displacement_mm); });
  else
    for_each_sample(run, first * kBlockSize, (last + 1) * kBlockSize - 1, [&](const SampleRow& r) { take(r.t, r.disp, r.force); });
  std::erase_if(out, [](const Bucket& b) { return b.n == 0; });
  return out;
}

void Reads::for_each_sample(std::int64_t run, std::int64_t seq0, std::int64_t seq1, const std::function<void(const SampleRow&)>& f) {
  Statement st(db_, "SELECT seq, t, cmd, disp, force, status FROM samples WHERE run_id = ? AND seq BETWEEN ? AND ? ORDER BY seq");
  st.bind(1, run).bind(2, seq0).bind(3, seq1);
  while (st.step()) f(SampleRow{run, st.column_int(0), st.column_double(1), st.column_double(2), st.column_double(3), st.column_double(4), st.column_int(5)});
}

void Reads::for_each_shaker_sample(std::int64_t run, std::int64_t seq0, std::int64_t seq1, const std::function<void(const ShakerRow&)>& f) {
  Statement st(db_,
               "SELECT seq, t, drive_frequency_hz, drive_amplitude_mm, base_displacement_mm, mass_displacement_mm, base_accel_m_s2, "
               "mass_accel_m_s2, status FROM shaker_samples WHERE run_id = ? AND seq BETWEEN ? AND ? ORDER BY seq");
  st.bind(1, run).bind(2, seq0).bind(3, seq1);
  while (st.step()) {
    std::array<double, 6> v{};
    for (int k = 0; k < 6; ++k) v[static_cast<std::size_t>(k)] = st.column_double(k + 2);
    const ShakerRow r{run, st.column_int(0), st.column_double(1), domain::shaker_sample(v), st.column_int(8)};
    f(r);
  }
}

std::int64_t Reads::max_shaker_seq(std::int64_t run) {
  Statement st(db_, "SELECT coalesce(max(seq), -1) FROM shaker_samples WHERE run_id = ?");
  st.bind(1, run);
  st.step();
  return st.column_int(0);
}

std::string Reads::integrity_check() {
  Statement st(db_, "PRAGMA integrity_check");
  std::string out;
  while (st.step()) out += (out.empty() ? "" : "; ") + st.column_text(0);
  return out;
}

}  // namespace hystlab::db
