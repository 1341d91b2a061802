#pragma once
// Reads of the lab database (hystlab.* in PostgreSQL, filled by every daemon's Replicator): what
// the lab view and `hystlab lab ...` show. Rows are keyed by (daemon, the daemon's own id); names
// come from the views of pg_schema.cpp. Read-only: nothing here writes.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "hystlab/db/pg.hpp"
#include "hystlab/db/store.hpp"

namespace hystlab::db {

struct LabDaemon {
  int id = 0;
  std::string lab, name, software, first_seen, last_seen, url;
};
struct LabRig {
  int daemon_id = 0;
  std::string daemon, name, last_campaign_state;
  std::int64_t id = 0, last_campaign = 0;  // 0: none
};
struct LabCampaign {
  int daemon_id = 0;
  std::string lab, daemon, rig, kind, state, specimen, created_at, updated_at;
  std::int64_t id = 0;
  std::string plan;  // JSON text (campaign() only)
};
struct LabRun {
  std::int64_t id = 0, samples = 0;
  std::string role, state, started_at, ended_at;
  bool shaker = false;  // its samples are a shaker's
  std::int64_t campaign = 0;
};
struct LabEvent {
  std::int64_t id = 0;
  std::string at, kind, from_state, to_state, detail;
};
struct LabTable {
  int daemon_id = 0;
  std::string daemon, specimen, method, created_at, accuracy;  // accuracy: JSON text or empty
  std::int64_t id = 0, campaign = 0;
  int n = 0;
  double range_lo = 0, range_hi = 0;
};
struct LabFilter {
  std::string lab, daemon, specimen, kind;  // empty: any
  int limit = 200;
};
// A run's samples in buckets of consecutive samples: each column's min and max per bucket (every
// peak kept), as the rig's own overview; columns: t, then the rig kind's signals.
struct LabOverview {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> min, max;  // [column][bucket]
};

class LabReads {
 public:
  explicit LabReads(PgConnection& pg) noexcept : pg_(pg) {}
  std::vector<LabDaemon> daemons(const std::string& lab = {});
  std::vector<LabRig> rigs(const std::string& lab = {});
  std::vector<LabCampaign> campaigns(const LabFilter& f);
  // lab: empty for any (a daemon's name is unique in its lab only).
  std::optional<LabCampaign> campaign(const std::string& daemon, std::int64_t id, const std::string& lab = {});
  std::vector<LabRun> runs(int daemon_id, std::int64_t campaign);
  // One run of a daemon, or none (its campaign: campaign_of).
  std::optional<LabRun> run(int daemon_id, std::int64_t id);
  std::vector<LabEvent> events(int daemon_id, std::int64_t campaign, int limit = 500);
  std::vector<LabTable> tables(const LabFilter& f);
  std::vector<LabTable> campaign_tables(int daemon_id, std::int64_t campaign);
  std::optional<std::string> table_document(const std::string& daemon, std::int64_t id);
  LabOverview overview(int daemon_id, std::int64_t run, bool shaker, int buckets);

 private:
  PgConnection& pg_;
};

}  // namespace hystlab::db
