#include "hystlab/db/replicator.hpp"

#include <algorithm>
#include <charconv>
#include <functional>
#include <optional>
#include <set>
#include <utility>

namespace hystlab::db {
// Each replicated table by its columns, the same names in SQLite and in hystlab.* (where
// daemon_id comes first), and the key an upsert resolves on.
struct detail::TableSpec {
  const char* name;
  const char* columns;
  const char* key;
};
namespace {
using Spec = detail::TableSpec;
constexpr Spec kRigs{"rigs", "id, name, config, created_at", "id"};
constexpr Spec kCampaigns{"campaigns", "id, rig_id, kind, plan, state, created_at, updated_at", "id"};
constexpr Spec kRuns{"runs", "id, campaign_id, started_at, wall_anchor_unix, monotonic_anchor_s, ended_at, state, role", "id"};
constexpr Spec kAppended[] = {
    {"events", "id, campaign_id, run_id, at, t, kind, from_state, to_state, detail", "id"},
    {"fot_nodes", "id, run_id, alpha, beta, force_alpha, force_alpha_beta, t", "id"},
    {"tables", "id, campaign_id, run_id, method, n, range_lo, range_hi, created_at, accuracy, document", "id"},
    {"io_stats", "id, rig_id, at, stats", "id"},
};
constexpr Spec kSweepPoints{"transmissibility",
                            "id, run_id, frequency_hz, base_amplitude_mm, mass_amplitude_mm, ratio, phase_rad, step, demand_mm, direction, detail, "
                            "predicted_ratio, predicted_phase_rad",
                            "id"};
constexpr Spec kLoops{"loops", "run_id, k, phase, figures", "run_id, k"};
constexpr Spec kSamples[] = {
    {"samples", "seq, t, cmd, disp, force, status", "seq"},
    {"shaker_samples", "seq, t, drive_frequency_hz, drive_amplitude_mm, base_displacement_mm, mass_displacement_mm, base_accel_m_s2, mass_accel_m_s2, status",
     "seq"},
};
// Campaigns in these states never change again; any other is read again every pass.
constexpr const char* kOpenCampaigns = "SELECT id FROM hystlab.campaigns WHERE daemon_id = $1 AND state NOT IN ('completed', 'aborted', 'failed')";
constexpr const char* kOpenRuns = "SELECT id FROM hystlab.runs WHERE daemon_id = $1 AND ended_at IS NULL";

void append_int(std::string& out, std::int64_t v) {
  char buf[24];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, end);
}

// One SQLite row as a COPY text line after `prefix` (the daemon's id and any key before it).
void encode_row(const Statement& st, int columns, std::string& out) {
  for (int c = 0; c < columns; ++c) {
    out += '\t';
    switch (st.column_type(c)) {
      case Statement::Type::integer:
        append_int(out, st.column_int(c));
        break;
      case Statement::Type::real:
        append_copy_double(out, st.column_double(c));
        break;
      case Statement::Type::text:
        append_copy_text(out, st.column_view(c));
        break;
      default:
        out += "\\N";  // NULL (and a BLOB, which no replicated column holds)
    }
  }
  out += '\n';
}

int column_count(const char* columns) { return static_cast<int>(std::count(columns, columns + std::char_traits<char>::length(columns), ',')) + 1; }

std::string json_ids(const std::vector<std::int64_t>& ids) {
  std::string s = "[";
  for (const std::int64_t id : ids) {
    if (s.size() > 1) s += ',';
    append_int(s, id);
  }
  return s + "]";
}

// f(), a PostgreSQL error naming the table it was copying (one row refused stops replication
// until it is mended: the status must say where).
template <class F>
std::int64_t naming(const char* table, F f) {
  try {
    return f();
  } catch (const PgSchemaError&) {
    throw;
  } catch (const PgError& e) {
    throw PgError(std::string(e.what()) + " (replicating " + table + ")", e.sqlstate);
  }
}

std::string upsert_set(const char* columns, const char* key) {
  std::string set, col;
  const std::string cols = std::string(columns) + ",";
  const std::string keys = std::string(", ") + key + ",";
  for (const char ch : cols) {
    if (ch != ',') {
      if (ch != ' ') col += ch;
      continue;
    }
    if (keys.find(" " + col + ",") == std::string::npos) set += (set.empty() ? "" : ", ") + col + " = excluded." + col;
    col.clear();
  }
  return set;
}
}  // namespace

Replicator::Replicator(std::string sqlite_path, ReplicaIdentity id, std::string conninfo, std::string password, std::size_t batch_rows)
    : sqlite_path_(std::move(sqlite_path)), id_(std::move(id)), conninfo_(std::move(conninfo)), password_(std::move(password)), batch_rows_(batch_rows) {}
Replicator::~Replicator() = default;

bool Replicator::connected() const noexcept { return pg_ && pg_->ok(); }
void Replicator::disconnect() noexcept { pg_.reset(); }

void Replicator::connect() {
  pg_.reset();
  temp_tables_.clear();  // a session's temporary tables went with it
  if (!lite_) lite_ = std::make_unique<Database>(sqlite_path_, false);
  std::string store;
  {
    Statement st(*lite_, "SELECT id FROM store_identity");
    if (!st.step()) throw DbError("the daemon's database '" + sqlite_path_ + "' has no identity (store_identity): not migrated", 0);
    store = st.column_text(0);
  }
  auto pg = std::make_unique<PgConnection>(conninfo_, password_);
  // Which daemon this session is, for whoever reads pg_stat_activity (a DBA; the kill -9 test).
  const std::string app = "hystlabd " + id_.daemon;
  (void)pg->query("SELECT set_config('application_name', $1, false)", {app.c_str()});
  pg_migrate(*pg);
  // This daemon's id in the lab, claimed by this SQLite file: another file under the same name
  // (a second daemon given the same lab.daemon, or a new file) would start its ids again under
  // the first one's marks and overwrite its rows; it is refused, naming the field.
  const PgResult d = pg->query(
      "INSERT INTO hystlab.daemons(lab, name, software, url, store) VALUES($1, $2, $3, nullif($4, ''), $5) "
      "ON CONFLICT(lab, name) DO UPDATE SET software = excluded.software, url = excluded.url, last_seen = now(), "
      "store = coalesce(hystlab.daemons.store, excluded.store) RETURNING id, store",
      {id_.lab.c_str(), id_.daemon.c_str(), id_.software.c_str(), id_.url.c_str(), store.c_str()});
  if (d.text(0, 1) != store)
    throw PgSchemaError("PostgreSQL: lab.daemon '" + id_.daemon + "' of lab '" + id_.lab + "' is replicated from another SQLite file (store " + d.text(0, 1) +
                            "; this one is " + store + "): give this daemon a name of its own in lab.daemon",
                        "");
  daemon_id_ = static_cast<int>(d.integer(0, 0));
  daemon_text_ = std::to_string(daemon_id_);
  // The marks as PostgreSQL committed them: after any failure, the truth is there, never here.
  marks_.clear();
  const PgResult m = pg->query("SELECT tbl, key, mark FROM hystlab.marks WHERE daemon_id = $1", {daemon_text_.c_str()});
  for (int r = 0; r < m.rows(); ++r) marks_[{m.text(r, 0), m.integer(r, 1)}] = m.integer(r, 2);
  pg_ = std::move(pg);
}

std::int64_t Replicator::mark(const char* table, std::int64_t key) const {
  const auto it = marks_.find({table, key});
  return it == marks_.end() ? -1 : it->second;
}

void Replicator::save_mark(const char* table, std::int64_t key, std::int64_t value) {
  const std::string k = std::to_string(key), v = std::to_string(value);
  pg_->query(
      "INSERT INTO hystlab.marks(daemon_id, tbl, key, mark) VALUES($1, $2, $3, $4) "
      "ON CONFLICT(daemon_id, tbl, key) DO UPDATE SET mark = excluded.mark",
      {daemon_text_.c_str(), table, k.c_str(), v.c_str()});
}

std::vector<std::int64_t> Replicator::pg_ids(const char* sql) {
  const PgResult r = pg_->query(sql, {daemon_text_.c_str()});
  std::vector<std::int64_t> ids;
  for (int k = 0; k < r.rows(); ++k) ids.push_back(r.integer(k, 0));
  return ids;
}

PassResult Replicator::pass(int max_batches) {
  if (!connected()) connect();
  // The lab sees this daemon alive (hystlab.daemons.last_seen), at most every 10 s.
  if (const auto now = std::chrono::steady_clock::now(); now - last_seen_ > std::chrono::seconds(10)) {
    pg_->query("UPDATE hystlab.daemons SET last_seen = now() WHERE id = $1", {daemon_text_.c_str()});
    last_seen_ = now;
  }
  PassResult out;
  bool more = false;
  std::int64_t backlog = 0;
  for (const Spec& s : kSamples) out.samples += naming(s.name, [&] { return copy_samples(s, max_batches, more, backlog); });
  backlog_samples_ = backlog;
  out.rows += out.samples;
  for (const Spec& s : kAppended) out.rows += naming(s.name, [&] { return copy_appended(s); });
  out.rows += naming("campaigns, runs, sweep points, loops and rigs", [&] { return copy_changing(); });
  out.caught_up = !more;
  return out;
}

// Every run's samples past its mark, a batch of batch_rows_ to a transaction with its mark.
std::int64_t Replicator::copy_samples(const Spec& s, int max_batches, bool& more, std::int64_t& backlog) {
  std::vector<std::int64_t> runs;
  {
    Statement st(*lite_, "SELECT id FROM runs ORDER BY id");
    while (st.step()) runs.push_back(st.column_int(0));
  }
  Statement newest(*lite_, std::string("SELECT max(seq) FROM ") + s.name + " WHERE run_id = ?");
  std::int64_t copied = 0;
  int batches = 0;
  for (const std::int64_t run : runs) {
    newest.reset();
    newest.bind(1, run);
    if (!newest.step() || newest.column_is_null(0)) {
      newest.reset();
      continue;
    }
    const std::int64_t upto = newest.column_int(0);
    newest.reset();  // no read transaction left open across the COPYs below
    std::int64_t from = mark(s.name, run);
    while (from < upto) {
      if (batches >= max_batches) {
        more = true;
        break;
      }
      const std::int64_t n = copy_run_samples(s, run, from);
      if (n == 0) break;
      copied += n;
      ++batches;
      from = mark(s.name, run);
    }
    backlog += std::max<std::int64_t>(0, upto - from);
  }
  return copied;
}

// One batch of a run's samples, streamed: each piece of COPY text goes to the server while the next
// is read and encoded (the server parses as SQLite reads). The batch's read stays open for the
// batch alone (at most batch_rows_ samples; the connection's user timeout bounds a server gone).
std::int64_t Replicator::copy_run_samples(const Spec& s, std::int64_t run, std::int64_t from) {
  constexpr std::size_t kPiece = 64 * 1024;
  const int columns = column_count(s.columns);
  std::int64_t n = 0, last = from;
  PgTransaction tx(*pg_);
  {
    Statement st(*lite_, std::string("SELECT ") + s.columns + " FROM " + s.name + " WHERE run_id = ? AND seq > ? ORDER BY seq LIMIT ?");
    st.bind(1, run).bind(2, from).bind(3, static_cast<std::int64_t>(batch_rows_));
    std::optional<PgCopy> copy;
    buf_.clear();
    while (st.step()) {
      if (!copy) copy.emplace(*pg_, std::string("COPY hystlab.") + s.name + "(daemon_id, run_id, " + s.columns + ") FROM STDIN");
      buf_ += daemon_text_;
      buf_ += '\t';
      append_int(buf_, run);
      encode_row(st, columns, buf_);
      last = st.column_int(0);
      ++n;
      if (buf_.size() >= kPiece) copy->put(buf_), buf_.clear();
    }
    if (!copy) return 0;  // nothing past the mark (the transaction rolls back, empty)
    copy->put(buf_);
    copy->finish();
  }
  save_mark(s.name, run, last);
  tx.commit();
  marks_[{s.name, run}] = last;
  return n;
}

// Rows that never change, past their table's mark (key 0).
std::int64_t Replicator::copy_appended(const Spec& s) {
  std::int64_t total = 0;
  const int columns = column_count(s.columns);
  for (;;) {
    buf_.clear();
    std::int64_t n = 0, last = 0;
    {  // finalized before PostgreSQL is called
      Statement st(*lite_, std::string("SELECT ") + s.columns + " FROM " + s.name + " WHERE id > ? ORDER BY id LIMIT ?");
      st.bind(1, mark(s.name, 0)).bind(2, static_cast<std::int64_t>(batch_rows_));
      while (st.step()) {
        buf_ += daemon_text_;
        encode_row(st, columns, buf_);
        last = st.column_int(0);
        ++n;
      }
    }
    if (n == 0) return total;
    PgTransaction tx(*pg_);
    pg_->copy_in(std::string("COPY hystlab.") + s.name + "(daemon_id, " + s.columns + ") FROM STDIN", buf_);
    save_mark(s.name, 0, last);
    tx.commit();
    marks_[{s.name, 0}] = last;
    total += n;
    if (n < static_cast<std::int64_t>(batch_rows_)) return total;
  }
}

// Rows selected by `where` (?1: a JSON list of ids) as COPY text, with their first column (an id).
Replicator::Rows Replicator::read_rows(const Spec& s, const std::string& where, const std::string& ids) {
  Rows out;
  Statement st(*lite_, std::string("SELECT ") + s.columns + " FROM " + s.name + " WHERE " + where);
  if (where.find("?1") != std::string::npos) st.bind(1, std::string_view(ids));
  const int columns = column_count(s.columns);
  while (st.step()) {
    out.text += daemon_text_;
    encode_row(st, columns, out.text);
    out.ids.push_back(st.column_int(0));
  }
  return out;
}

// The rows upserted in one transaction, with the table's mark (key 0) moved to `new_mark` when >=
// 0 and `also` (more statements of the same transaction) before the commit. An unchanged row is
// not written again (no dead row for a campaign or rig read again every pass).
void Replicator::write_upsert(const Spec& s, const Rows& rows, std::int64_t new_mark, const std::function<void()>& also) {
  if (rows.ids.empty() && !also) return;
  const std::string temp = std::string("up_") + s.name;
  if (!rows.ids.empty() && temp_tables_.insert(temp).second)
    pg_->exec("CREATE TEMP TABLE IF NOT EXISTS " + temp + " (LIKE hystlab." + s.name + ") ON COMMIT DELETE ROWS");
  PgTransaction tx(*pg_);
  if (!rows.ids.empty()) {
    pg_->copy_in("COPY " + temp + "(daemon_id, " + s.columns + ") FROM STDIN", rows.text);
    pg_->exec("INSERT INTO hystlab." + std::string(s.name) + " AS t SELECT * FROM " + temp + " ON CONFLICT (daemon_id, " + s.key + ") DO UPDATE SET " +
              upsert_set(s.columns, s.key) + " WHERE (t.*) IS DISTINCT FROM (excluded.*)");
  }
  if (also) also();
  if (new_mark >= 0) save_mark(s.name, 0, new_mark);
  tx.commit();
  if (new_mark >= 0) marks_[{s.name, 0}] = new_mark;
}

// Rows that change, read from one SQLite snapshot (a run's sweep points and loop figures with the
// run itself, so that PostgreSQL never holds a run as ended without its last children: the next
// pass reads a run's children again as long as PostgreSQL holds it open), then written, the
// snapshot ended first (a PostgreSQL slow or gone never holds the SQLite file's WAL).
std::int64_t Replicator::copy_changing() {
  const std::vector<std::int64_t> open_runs = pg_ids(kOpenRuns), open_campaigns = pg_ids(kOpenCampaigns);
  const std::string runs_ids = json_ids(open_runs), campaign_ids = json_ids(open_campaigns);
  const std::int64_t runs_mark = mark("runs", 0);
  const std::string run_open = "(run_id IN (SELECT value FROM json_each(?1)) OR run_id > " + std::to_string(runs_mark) + ")";
  Rows points, loops, runs, campaigns, rigs;
  {
    Transaction snapshot(*lite_, false);  // a read transaction: one snapshot for every read here
    points = read_rows(kSweepPoints, "id > " + std::to_string(mark(kSweepPoints.name, 0)) + " OR " + run_open + " ORDER BY id", runs_ids);
    loops = read_rows(kLoops, run_open + " ORDER BY run_id, k", runs_ids);
    runs = read_rows(kRuns, "id > " + std::to_string(runs_mark) + " OR id IN (SELECT value FROM json_each(?1)) ORDER BY id", runs_ids);
    campaigns = read_rows(kCampaigns, "id > " + std::to_string(mark("campaigns", 0)) + " OR id IN (SELECT value FROM json_each(?1)) ORDER BY id", campaign_ids);
    rigs = read_rows(kRigs, "1 ORDER BY id", {});
  }
  const auto newest = [this](const Spec& s, const Rows& r) {
    return r.ids.empty() ? -1 : std::max(mark(s.name, 0), *std::max_element(r.ids.begin(), r.ids.end()));
  };
  write_upsert(kSweepPoints, points, newest(kSweepPoints, points), {});
  write_upsert(kLoops, loops, -1, {});
  // A run PostgreSQL holds open that SQLite no longer has (a validation run that never started
  // is removed with its campaign's end) is removed there too, and the runs' mark goes back below
  // it: SQLite gives a removed newest id to the next run, which must be copied as new.
  std::vector<std::int64_t> gone;
  for (const std::int64_t r : open_runs)
    if (std::find(runs.ids.begin(), runs.ids.end(), r) == runs.ids.end()) gone.push_back(r);
  std::int64_t new_runs_mark = newest(kRuns, runs);
  if (!gone.empty()) new_runs_mark = std::min(new_runs_mark < 0 ? runs_mark : new_runs_mark, *std::min_element(gone.begin(), gone.end()) - 1);
  write_upsert(
      kRuns, runs, new_runs_mark, gone.empty() ? std::function<void()>() : [&] {
        const std::string list = "{" + json_ids(gone).substr(1, json_ids(gone).size() - 2) + "}";
        pg_->query("DELETE FROM hystlab.runs WHERE daemon_id = $1 AND id = ANY($2::bigint[])", {daemon_text_.c_str(), list.c_str()});
        pg_->query("DELETE FROM hystlab.marks WHERE daemon_id = $1 AND tbl IN ('samples', 'shaker_samples') AND key = ANY($2::bigint[])",
                   {daemon_text_.c_str(), list.c_str()});
      });
  for (const std::int64_t g : gone) marks_.erase({"samples", g}), marks_.erase({"shaker_samples", g});
  write_upsert(kCampaigns, campaigns, newest(kCampaigns, campaigns), {});
  write_upsert(kRigs, rigs, -1, {});
  return static_cast<std::int64_t>(points.ids.size() + loops.ids.size() + runs.ids.size() + campaigns.ids.size() + rigs.ids.size());
}

}  // namespace hystlab::db
