// The lab database's schema (docs/FORMATS.md, "The lab database"): hystlab.* in PostgreSQL, one
// row per daemon in hystlab.daemons, every replicated row keyed by (daemon_id, the daemon's own
// id), the high-water marks in hystlab.marks, and views a dashboard reads directly.
#include <string>

#include "hystlab/db/replicator.hpp"

namespace hystlab::db {
namespace {
// Samples are partitioned by hash of (daemon_id, run_id): a run's samples sit in one partition
// and a query for a run reads one of them; 16 partitions keep each under ~10^8 rows at 10^9
// (docs/LAB.md says how a lab goes beyond).
std::string partitions(const std::string& table) {
  std::string s;
  for (int k = 0; k < 16; ++k)
    s += "CREATE TABLE hystlab." + table + "_p" + std::to_string(k) + " PARTITION OF hystlab." + table + " FOR VALUES WITH (MODULUS 16, REMAINDER " +
         std::to_string(k) + ");\n";
  return s;
}

// Migration k takes the lab database from version k to k + 1. Append only.
std::string migration(int k) {
  if (k == 0)
    return R"sql(
CREATE TABLE hystlab.daemons(
  id serial PRIMARY KEY, lab text NOT NULL, name text NOT NULL, software text, url text, store text,
  first_seen timestamptz NOT NULL DEFAULT now(), last_seen timestamptz NOT NULL DEFAULT now(), UNIQUE(lab, name));
CREATE TABLE hystlab.marks(
  daemon_id integer NOT NULL, tbl text NOT NULL, key bigint NOT NULL, mark bigint NOT NULL, PRIMARY KEY(daemon_id, tbl, key));
CREATE TABLE hystlab.rigs(
  daemon_id integer NOT NULL, id bigint NOT NULL, name text NOT NULL, config jsonb, created_at timestamptz, PRIMARY KEY(daemon_id, id));
CREATE TABLE hystlab.campaigns(
  daemon_id integer NOT NULL, id bigint NOT NULL, rig_id bigint, kind text, plan jsonb, state text,
  created_at timestamptz, updated_at timestamptz, PRIMARY KEY(daemon_id, id));
CREATE TABLE hystlab.runs(
  daemon_id integer NOT NULL, id bigint NOT NULL, campaign_id bigint, started_at timestamptz, wall_anchor_unix float8,
  monotonic_anchor_s float8, ended_at timestamptz, state text, role text, PRIMARY KEY(daemon_id, id));
CREATE TABLE hystlab.events(
  daemon_id integer NOT NULL, id bigint NOT NULL, campaign_id bigint, run_id bigint, at timestamptz, t float8, kind text,
  from_state text, to_state text, detail text, PRIMARY KEY(daemon_id, id));
CREATE INDEX events_by_campaign ON hystlab.events(daemon_id, campaign_id, id);
CREATE TABLE hystlab.samples(
  daemon_id integer NOT NULL, run_id bigint NOT NULL, seq bigint NOT NULL, t float8 NOT NULL, cmd float8, disp float8, force float8,
  status integer, PRIMARY KEY(daemon_id, run_id, seq)) PARTITION BY HASH(daemon_id, run_id);
CREATE TABLE hystlab.shaker_samples(
  daemon_id integer NOT NULL, run_id bigint NOT NULL, seq bigint NOT NULL, t float8 NOT NULL, drive_frequency_hz float8,
  drive_amplitude_mm float8, base_displacement_mm float8, mass_displacement_mm float8, base_accel_m_s2 float8, mass_accel_m_s2 float8,
  status integer, PRIMARY KEY(daemon_id, run_id, seq)) PARTITION BY HASH(daemon_id, run_id);
CREATE TABLE hystlab.fot_nodes(
  daemon_id integer NOT NULL, id bigint NOT NULL, run_id bigint, alpha float8, beta float8, force_alpha float8, force_alpha_beta float8,
  t float8, PRIMARY KEY(daemon_id, id));
CREATE TABLE hystlab.tables(
  daemon_id integer NOT NULL, id bigint NOT NULL, campaign_id bigint, run_id bigint, method text, n integer, range_lo float8,
  range_hi float8, created_at timestamptz, accuracy text, document jsonb, PRIMARY KEY(daemon_id, id));
CREATE TABLE hystlab.transmissibility(
  daemon_id integer NOT NULL, id bigint NOT NULL, run_id bigint, frequency_hz float8, base_amplitude_mm float8, mass_amplitude_mm float8,
  ratio float8, phase_rad float8, step integer, demand_mm float8, direction text, detail text, predicted_ratio float8,
  predicted_phase_rad float8, PRIMARY KEY(daemon_id, id));
CREATE TABLE hystlab.loops(
  daemon_id integer NOT NULL, run_id bigint NOT NULL, k integer NOT NULL, phase text, figures jsonb, PRIMARY KEY(daemon_id, run_id, k));
CREATE TABLE hystlab.io_stats(
  daemon_id integer NOT NULL, id bigint NOT NULL, rig_id bigint, at timestamptz, stats jsonb, PRIMARY KEY(daemon_id, id));
)sql" + partitions("samples") +
           partitions("shaker_samples") + R"sql(
-- What a dashboard reads: names instead of ids, across every daemon of every lab.
CREATE VIEW hystlab.lab_campaigns AS
  SELECT d.lab, d.name AS daemon, r.name AS rig, c.id AS campaign, c.kind, c.state, c.plan->>'specimen' AS specimen,
         c.created_at, c.updated_at, c.daemon_id
  FROM hystlab.campaigns c JOIN hystlab.daemons d ON d.id = c.daemon_id
  LEFT JOIN hystlab.rigs r ON r.daemon_id = c.daemon_id AND r.id = c.rig_id;
CREATE VIEW hystlab.lab_rigs AS
  SELECT d.lab, d.name AS daemon, r.name AS rig, d.last_seen,
         (SELECT c.state FROM hystlab.campaigns c WHERE c.daemon_id = r.daemon_id AND c.rig_id = r.id ORDER BY c.id DESC LIMIT 1) AS last_campaign_state,
         (SELECT c.id FROM hystlab.campaigns c WHERE c.daemon_id = r.daemon_id AND c.rig_id = r.id ORDER BY c.id DESC LIMIT 1) AS last_campaign,
         r.daemon_id, r.id AS rig_id
  FROM hystlab.rigs r JOIN hystlab.daemons d ON d.id = r.daemon_id;
CREATE VIEW hystlab.lab_tables AS
  SELECT d.lab, d.name AS daemon, t.id AS table_id, t.campaign_id AS campaign, c.plan->>'specimen' AS specimen, t.method, t.n,
         t.range_lo, t.range_hi, t.created_at, t.accuracy,
         (CASE WHEN t.accuracy LIKE '{%' THEN (t.accuracy::jsonb #>> '{held_out,overall,rms_N}')::float8 END) AS held_out_rms_n,
         t.daemon_id
  FROM hystlab.tables t JOIN hystlab.daemons d ON d.id = t.daemon_id
  LEFT JOIN hystlab.campaigns c ON c.daemon_id = t.daemon_id AND c.id = t.campaign_id;
-- Per run: samples replicated (the run's mark), its rig-time span through the primary key (two
-- index probes, never a scan of the samples), and the run's data quality as the daemon measured
-- it (its "quality" event: rate, missed deadlines, gaps, losses). The CASE keeps the JSON cast off
-- events of other kinds (a command's detail is plain text).
CREATE VIEW hystlab.run_quality AS
  SELECT d.lab, d.name AS daemon, u.id AS run, u.campaign_id AS campaign, u.role, u.state, u.started_at, u.ended_at,
         m.mark + 1 AS samples,
         (SELECT s.t FROM hystlab.samples s WHERE s.daemon_id = u.daemon_id AND s.run_id = u.id ORDER BY s.seq DESC LIMIT 1) -
         (SELECT s.t FROM hystlab.samples s WHERE s.daemon_id = u.daemon_id AND s.run_id = u.id ORDER BY s.seq LIMIT 1) AS span_s,
         (q.q->>'rate_hz')::float8 AS rate_hz, (q.q->>'requested_rate_hz')::float8 AS requested_rate_hz,
         (q.q->>'missed_deadlines')::bigint AS missed_deadlines, (q.q->>'gaps')::bigint AS gaps,
         (q.q->>'longest_gap_s')::float8 AS longest_gap_s, (q.q->>'dropped')::bigint AS dropped,
         (q.q->>'lost_samples')::bigint AS lost_samples, (q.q->>'io_errors')::bigint AS io_errors,
         u.daemon_id
  FROM hystlab.runs u JOIN hystlab.daemons d ON d.id = u.daemon_id
  LEFT JOIN hystlab.marks m ON m.daemon_id = u.daemon_id AND m.tbl IN ('samples', 'shaker_samples') AND m.key = u.id
  LEFT JOIN LATERAL (
    SELECT CASE WHEN e.kind = 'quality' THEN e.detail::jsonb END AS q FROM hystlab.events e
    WHERE e.daemon_id = u.daemon_id AND e.campaign_id = u.campaign_id AND e.kind = 'quality'
      AND (CASE WHEN e.kind = 'quality' THEN (e.detail::jsonb->>'run')::bigint END) = u.id
    ORDER BY e.id DESC LIMIT 1) q ON true;
)sql";
  return {};
}
}  // namespace

int pg_schema_version(PgConnection& c) {
  const PgResult r = c.query(
      "SELECT CASE WHEN to_regclass('hystlab.schema_version') IS NULL THEN 0 "
      "ELSE (SELECT coalesce(max(version), 0) FROM hystlab.schema_version) END");
  return static_cast<int>(r.integer(0, 0));
}

void pg_migrate(PgConnection& c) {
  PgTransaction tx(c);
  // One daemon migrates at a time; the others wait here and find the work done.
  c.exec("SELECT pg_advisory_xact_lock(4702631)");
  c.exec("CREATE SCHEMA IF NOT EXISTS hystlab");
  c.exec("CREATE TABLE IF NOT EXISTS hystlab.schema_version(version integer NOT NULL, at timestamptz NOT NULL DEFAULT now())");
  const int v = pg_schema_version(c);
  if (v > kPgSchemaVersion)
    throw PgSchemaError("PostgreSQL: the lab database has hystlab schema version " + std::to_string(v) + ", newer than this hystlabd's (" +
                            std::to_string(kPgSchemaVersion) + "): not replicating to it (update this daemon)",
                        "");
  for (int k = v; k < kPgSchemaVersion; ++k) {
    c.exec(migration(k));
    c.exec("INSERT INTO hystlab.schema_version(version) VALUES(" + std::to_string(k + 1) + ")");
  }
  tx.commit();
}

}  // namespace hystlab::db
