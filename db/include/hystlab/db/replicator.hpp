#pragma once
// Replication of one daemon's SQLite store into the lab's PostgreSQL (docs/LAB.md): SQLite stays
// the source of truth; the lab database holds many daemons' rows keyed by (daemon_id, local id).
//
// Nothing lost, nothing twice: every batch of rows is committed in PostgreSQL in one transaction
// with the high-water mark that covers it (hystlab.marks), so an outage of either side, a kill -9
// mid-batch or a restart resumes exactly where the last commit stopped. Append-only rows (samples
// per run, events, FOT nodes, tables) are copied past their mark; rows that change (campaigns,
// runs, a sweep's points and loop figures of a run still open) are upserted until PostgreSQL has
// them in a final state, read from one SQLite snapshot so that a run is never closed there before
// its last children are.
//
// Thread rule: one thread owns a Replicator (its own read connection to the SQLite file: WAL
// readers never block the daemon's writer). Errors throw PgError (PostgreSQL; sqlstate class 08:
// the link) or DbError (SQLite).
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "hystlab/db/pg.hpp"
#include "hystlab/db/sqlite.hpp"

namespace hystlab::db {
namespace detail {
struct TableSpec;
}

// The lab database's schema, migrated by the daemon (docs/FORMATS.md, "The lab database").
inline constexpr int kPgSchemaVersion = 1;
// A lab database migrated by a newer hystlab: nothing is written to it.
struct PgSchemaError : PgError {
  using PgError::PgError;
};
// Takes the lab database to kPgSchemaVersion (under an advisory lock: daemons starting together).
void pg_migrate(PgConnection& c);
[[nodiscard]] int pg_schema_version(PgConnection& c);

struct ReplicaIdentity {
  std::string lab, daemon, software;
  std::string url;  // the daemon's page ("" when not said)
};

struct PassResult {
  std::int64_t rows = 0;     // rows of every table committed by this pass
  std::int64_t samples = 0;  // of which samples (load frame and shaker)
  bool caught_up = false;    // everything SQLite held when the pass began is in PostgreSQL
};

class Replicator {
 public:
  Replicator(std::string sqlite_path, ReplicaIdentity id, std::string conninfo, std::string password, std::size_t batch_rows = 20000);
  ~Replicator();
  Replicator(const Replicator&) = delete;
  Replicator& operator=(const Replicator&) = delete;

  // Connects, migrates, registers this daemon and reads its marks back. Throws.
  void connect();
  void disconnect() noexcept;
  [[nodiscard]] bool connected() const noexcept;
  // One pass over every table; at most max_batches sample batches (the rest: the next pass).
  PassResult pass(int max_batches = 50);
  // Samples in SQLite not yet in PostgreSQL, as of the last pass.
  [[nodiscard]] std::int64_t backlog_samples() const noexcept { return backlog_samples_; }
  [[nodiscard]] int daemon_id() const noexcept { return daemon_id_; }

 private:
  using Spec = detail::TableSpec;
  std::int64_t copy_samples(const Spec& s, int max_batches, bool& more, std::int64_t& backlog);
  std::int64_t copy_run_samples(const Spec& s, std::int64_t run, std::int64_t from);
  std::int64_t copy_appended(const Spec& s);
  std::int64_t copy_changing();
  struct Rows {
    std::string text;               // COPY text
    std::vector<std::int64_t> ids;  // each row's first column
  };
  Rows read_rows(const Spec& s, const std::string& where, const std::string& ids);
  void write_upsert(const Spec& s, const Rows& rows, std::int64_t new_mark, const std::function<void()>& also);
  std::vector<std::int64_t> pg_ids(const char* sql);
  [[nodiscard]] std::int64_t mark(const char* table, std::int64_t key) const;
  void save_mark(const char* table, std::int64_t key, std::int64_t value);

  std::string sqlite_path_;
  ReplicaIdentity id_;
  std::string conninfo_, password_;
  std::size_t batch_rows_;
  std::unique_ptr<Database> lite_;
  std::unique_ptr<PgConnection> pg_;
  int daemon_id_ = 0;
  std::string daemon_text_;
  std::map<std::pair<std::string, std::int64_t>, std::int64_t> marks_;  // (table, key) -> mark, as committed
  std::int64_t backlog_samples_ = 0;
  std::chrono::steady_clock::time_point last_seen_{};
  std::set<std::string> temp_tables_;  // created on this connection
  std::string buf_;                    // COPY text, reused
};

}  // namespace hystlab::db
