#include "hystlab/db/schema.hpp"

#include <string>

namespace hystlab::db {
namespace {
// Migration k takes the file from version k to k + 1. Append only; never edit a shipped step.
constexpr const char* kMigrations[] = {
    R"sql(
CREATE TABLE rigs(
  id INTEGER PRIMARY KEY, name TEXT NOT NULL UNIQUE, config TEXT NOT NULL, created_at TEXT NOT NULL);
CREATE TABLE campaigns(
  id INTEGER PRIMARY KEY, rig_id INTEGER NOT NULL REFERENCES rigs(id), kind TEXT NOT NULL,
  plan TEXT NOT NULL, state TEXT NOT NULL, created_at TEXT NOT NULL, updated_at TEXT NOT NULL);
CREATE INDEX campaigns_by_state ON campaigns(state);
CREATE TABLE runs(
  id INTEGER PRIMARY KEY, campaign_id INTEGER NOT NULL REFERENCES campaigns(id),
  started_at TEXT NOT NULL, wall_anchor_unix REAL NOT NULL, monotonic_anchor_s REAL NOT NULL,
  ended_at TEXT, state TEXT NOT NULL);
CREATE TABLE events(
  id INTEGER PRIMARY KEY, campaign_id INTEGER REFERENCES campaigns(id), run_id INTEGER REFERENCES runs(id),
  at TEXT NOT NULL, t REAL, kind TEXT NOT NULL, from_state TEXT, to_state TEXT, detail TEXT);
CREATE INDEX events_by_campaign ON events(campaign_id, id);
-- Samples are clustered by run and sequence: a run's samples are one contiguous range.
CREATE TABLE samples(
  run_id INTEGER NOT NULL, seq INTEGER NOT NULL, t REAL NOT NULL, cmd REAL, disp REAL, force REAL,
  status INTEGER, PRIMARY KEY(run_id, seq)) WITHOUT ROWID;
-- min/max per block of 1024 samples, written with them: overviews read 1/1024 of the rows.
CREATE TABLE sample_blocks(
  run_id INTEGER NOT NULL, block INTEGER NOT NULL, n INTEGER NOT NULL, t_min REAL, t_max REAL,
  disp_min REAL, disp_max REAL, force_min REAL, force_max REAL, PRIMARY KEY(run_id, block)) WITHOUT ROWID;
CREATE TABLE fot_nodes(
  id INTEGER PRIMARY KEY, run_id INTEGER NOT NULL REFERENCES runs(id), alpha REAL NOT NULL, beta REAL NOT NULL,
  force_alpha REAL NOT NULL, force_alpha_beta REAL NOT NULL, t REAL);
CREATE INDEX fot_nodes_by_run ON fot_nodes(run_id, id);
CREATE TABLE tables(
  id INTEGER PRIMARY KEY, campaign_id INTEGER REFERENCES campaigns(id), run_id INTEGER REFERENCES runs(id),
  method TEXT NOT NULL, n INTEGER NOT NULL, range_lo REAL NOT NULL, range_hi REAL NOT NULL,
  created_at TEXT NOT NULL, accuracy TEXT, document TEXT NOT NULL);
CREATE TABLE transmissibility(
  id INTEGER PRIMARY KEY, run_id INTEGER NOT NULL REFERENCES runs(id), frequency_hz REAL NOT NULL,
  base_amplitude_mm REAL, mass_amplitude_mm REAL, ratio REAL, phase_rad REAL);
CREATE TABLE io_stats(
  id INTEGER PRIMARY KEY, rig_id INTEGER REFERENCES rigs(id), at TEXT NOT NULL, stats TEXT NOT NULL);
)sql",
    // 2: operator commands for the daemon, once written by the CLI. Since stop 21 nothing reads or
    // writes 2 and 3 (commands reach hystlabd only through its interface, the HTTP API); they stay
    // so that an older hystlabd on the same file never finds them dropped under it.
    R"sql(
CREATE TABLE commands(
  id INTEGER PRIMARY KEY, campaign_id INTEGER NOT NULL REFERENCES campaigns(id), command TEXT NOT NULL,
  created_at TEXT NOT NULL, handled_at TEXT);
CREATE INDEX commands_pending ON commands(handled_at, id);
)sql",
    // 3: operator commands for a rig (reset, estop), apart from any campaign (unused since stop 21).
    R"sql(
CREATE TABLE rig_commands(
  id INTEGER PRIMARY KEY, rig TEXT NOT NULL, command TEXT NOT NULL, created_at TEXT NOT NULL, handled_at TEXT);
)sql",
    // 4: a run's role (its campaign's input, or the validation input the tables are scored on),
    // and the figures of every closed cycle of every run (models/loop_figures), as JSON.
    R"sql(
ALTER TABLE runs ADD COLUMN role TEXT NOT NULL DEFAULT 'campaign';
CREATE TABLE loops(
  run_id INTEGER NOT NULL REFERENCES runs(id), k INTEGER NOT NULL, phase TEXT NOT NULL, figures TEXT NOT NULL,
  PRIMARY KEY(run_id, k)) WITHOUT ROWID;
)sql",
    // 5: a shaker's samples in its own terms (the columns are domain::kShakerSignals' names; before, the
    // load frame's columns held base and mass displacement and the mass's acceleration), and a
    // sine step's place in its sweep, its whole record, and the isolator model's prediction.
    R"sql(
CREATE TABLE shaker_samples(
  run_id INTEGER NOT NULL, seq INTEGER NOT NULL, t REAL NOT NULL, drive_frequency_hz REAL, drive_amplitude_mm REAL,
  base_displacement_mm REAL, mass_displacement_mm REAL, base_accel_m_s2 REAL, mass_accel_m_s2 REAL, status INTEGER,
  PRIMARY KEY(run_id, seq)) WITHOUT ROWID;
ALTER TABLE transmissibility ADD COLUMN step INTEGER;
ALTER TABLE transmissibility ADD COLUMN demand_mm REAL;
ALTER TABLE transmissibility ADD COLUMN direction TEXT;
ALTER TABLE transmissibility ADD COLUMN detail TEXT;
ALTER TABLE transmissibility ADD COLUMN predicted_ratio REAL;
ALTER TABLE transmissibility ADD COLUMN predicted_phase_rad REAL;
)sql",
    // 6: the file's own identity, random, made once: the lab database (docs/LAB.md) keys a
    // daemon's rows by its name and checks that they keep coming from the same file (a new file
    // under an old name would start its ids again under the old high-water marks).
    R"sql(
CREATE TABLE store_identity(id TEXT NOT NULL);
INSERT INTO store_identity VALUES(lower(hex(randomblob(16))));
)sql",
};
constexpr int kMigrationCount = static_cast<int>(sizeof kMigrations / sizeof kMigrations[0]);
static_assert(kMigrationCount == kSchemaVersion);
}  // namespace

int schema_version(Database& db) {
  Statement st(db, "PRAGMA user_version");
  st.step();
  return static_cast<int>(st.column_int(0));
}

void migrate(Database& db) {
  const int v = schema_version(db);
  if (v > kSchemaVersion)
    throw DbError("database '" + db.path() + "' has schema version " + std::to_string(v) + ", newer than this hystlab (" + std::to_string(kSchemaVersion) +
                      "): refusing to touch it",
                  0);
  // Each step under the write lock, the version read again inside it: two processes opening a
  // new file at once (the daemon starting, a reader polling for it) both saw version 0, and the
  // second failed with "table commands already exists".
  for (int k = v; k < kSchemaVersion; ++k) {
    Transaction tx(db, true);
    if (schema_version(db) > k) continue;  // the other process did this step
    db.exec(kMigrations[k]);
    db.exec("PRAGMA user_version=" + std::to_string(k + 1));
    tx.commit();
  }
}

}  // namespace hystlab::db
