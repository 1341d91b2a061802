#pragma once
// One daemon's records read from the lab database (hystlab.* in PostgreSQL, as its Replicator
// copied them): a ReadSource (reads.hpp) like the daemon's own SQLite file, so that the lab view
// answers a daemon's read endpoints with the same JSON (web/src/read_routes.cpp) and
// `hystlab runs export --pg` writes the same CSV and HDF5 as an export from the file.
//
// What differs from the file, by design: a run's `samples` are those replicated so far (the run's
// high-water mark), rig time spans and overviews are computed from the samples (the file's block
// summaries are not copied), and times come back in the file's own form (ISO 8601, UTC, ms).
// Read-only; one thread at a time (one connection: the HDF5 export reads ahead on a thread of
// its own, never beside the caller).
#include <cstdint>
#include <optional>
#include <string>

#include "hystlab/db/pg.hpp"
#include "hystlab/db/reads.hpp"

namespace hystlab::db {

class PgReads final : public ReadSource {
 public:
  PgReads(PgConnection& pg, int daemon_id) noexcept : pg_(pg), daemon_(std::to_string(daemon_id)) {}
  // The daemon's id in the lab database, by its lab and name (none when it never replicated).
  [[nodiscard]] static std::optional<int> daemon_id(PgConnection& pg, const std::string& lab, const std::string& daemon);

  [[nodiscard]] std::optional<CampaignRow> campaign(std::int64_t id) override;
  [[nodiscard]] std::vector<CampaignRow> campaigns() override;
  [[nodiscard]] std::vector<EventRow> events(std::int64_t campaign_id) override;
  [[nodiscard]] std::vector<std::string> event_details(std::int64_t campaign_id, const std::string& kind) override;
  [[nodiscard]] std::string state_reason(std::int64_t campaign_id, domain::CampaignState state) override;
  [[nodiscard]] std::string rig_name(std::int64_t rig_id) override;
  [[nodiscard]] std::pair<std::string, std::string> rig_record(std::int64_t rig_id) override;
  [[nodiscard]] std::vector<std::pair<std::int64_t, std::string>> rigs() override;

  [[nodiscard]] std::optional<RunInfo> run(std::int64_t id) override;
  [[nodiscard]] std::vector<RunInfo> runs(std::int64_t campaign_id) override;
  [[nodiscard]] std::vector<std::int64_t> runs_of_campaign(std::int64_t campaign_id, std::optional<domain::RunRole> role = std::nullopt) override;
  [[nodiscard]] std::optional<std::pair<double, double>> time_span(std::int64_t run_id) override;
  [[nodiscard]] std::int64_t sample_count(std::int64_t run_id) override;
  [[nodiscard]] std::int64_t max_seq(std::int64_t run_id) override;
  [[nodiscard]] std::int64_t max_shaker_seq(std::int64_t run_id) override;
  [[nodiscard]] std::vector<Bucket> overview(std::int64_t run_id, double t0, double t1, int buckets, bool shaker = false) override;
  void for_each_sample(std::int64_t run_id, std::int64_t seq0, std::int64_t seq1, const std::function<void(const SampleRow&)>& f) override;
  void for_each_shaker_sample(std::int64_t run_id, std::int64_t seq0, std::int64_t seq1, const std::function<void(const ShakerRow&)>& f) override;
  std::int64_t read_xy(std::int64_t run_id, std::int64_t seq0, bool base_mass, std::vector<float>& x, std::vector<float>& y) override;

  [[nodiscard]] std::int64_t table_count(std::int64_t campaign_id) override;
  [[nodiscard]] std::vector<TableInfo> tables(std::optional<std::int64_t> campaign_id = std::nullopt) override;
  [[nodiscard]] std::optional<TableInfo> table(std::int64_t id) override;
  [[nodiscard]] std::optional<std::string> table_document(std::int64_t id) override;
  [[nodiscard]] std::optional<TableInfo> newest_table_of_rig(std::int64_t rig_id, const std::string& method) override;
  [[nodiscard]] std::optional<TableInfo> newest_table_of_campaign(std::int64_t campaign_id, const std::string& method) override;
  [[nodiscard]] std::vector<NodeInfo> nodes(std::int64_t campaign_id) override;
  [[nodiscard]] std::vector<std::tuple<double, double, double, double>> fot_nodes_of_campaign(std::int64_t campaign_id) override;
  [[nodiscard]] std::vector<TransmissibilityInfo> transmissibility(std::int64_t campaign_id) override;
  [[nodiscard]] std::vector<LoopInfo> loops(std::int64_t campaign_id) override;

 private:
  // sql with $1 the daemon and $2.. the further parameters.
  PgResult query(const std::string& sql, const std::vector<std::string>& more = {});
  std::vector<TableInfo> tables_where(const std::string& where, const std::vector<std::string>& more);
  PgConnection& pg_;
  std::string daemon_;
};

}  // namespace hystlab::db
