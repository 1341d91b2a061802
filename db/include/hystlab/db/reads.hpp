#pragma once
// The rows the API and the CLI read, as value types, and ReadSource: everything a reader of one
// daemon's records asks (the API's read routes, the CLI's views, the CSV and HDF5 exports). Two
// sources answer it: the daemon's own SQLite file (Reads, store.hpp) and that daemon's rows in the
// lab's PostgreSQL database (PgReads, pg_reads.hpp), so that the lab view answers the same
// endpoints with the same JSON and an export from the lab writes what the daemon's would. What
// they query lives in db/, and nowhere else holds SQL.
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "hystlab/domain/campaign.hpp"
#include "hystlab/domain/signals.hpp"

namespace hystlab::db {

struct RunInfo {
  std::int64_t id = 0, campaign = 0;
  std::string state, started_at, ended_at;  // ended_at empty while it runs
  double wall_anchor_unix = 0;
  std::int64_t samples = 0, nodes = 0;
  std::string role;  // campaign or validation
};

struct LoopInfo {  // one closed cycle of a run
  std::int64_t run = 0, k = 0;
  std::string phase, figures_json;
};

struct TableInfo {
  std::int64_t id = 0;
  std::optional<std::int64_t> campaign, run;
  std::string method;
  std::int64_t n = 0;
  double range_lo = 0, range_hi = 0;
  std::string created_at, accuracy_json;
};

struct NodeInfo {
  std::int64_t id = 0, campaign = 0, run = 0;
  double alpha = 0, beta = 0, force_alpha = 0, force_alpha_beta = 0, t = 0;
};

struct TransmissibilityInfo {
  std::int64_t id = 0, run = 0;
  double frequency_hz = 0, base_amplitude_mm = 0, mass_amplitude_mm = 0, ratio = 0, phase_rad = 0;
  // Since schema 5 (a sweep of several amplitudes and directions): 0, "" and NaN in older rows.
  std::int64_t step = 0;
  double demand_mm = 0;
  std::string direction, detail;  // detail: the step's whole record (JSON), "" when none
  double predicted_ratio = NAN, predicted_phase_rad = NAN;
};

struct SinePointRow {
  std::int64_t step = 0;
  double frequency_hz = 0, demand_mm = 0, base_amplitude_mm = 0, mass_amplitude_mm = 0, ratio = 0, phase_rad = 0;
  std::string direction, detail;
};

// An event with its campaign (the event stream reads them across campaigns).
struct EventInfo {
  std::int64_t id = 0, campaign = 0;
  std::string at, kind, from_state, to_state, detail;
};

struct SampleRow {  // a load frame's sample
  std::int64_t run_id = 0, seq = 0;
  double t = 0, cmd = 0, disp = 0, force = 0;
  std::int64_t status = 0;
};

struct ShakerRow {  // a shaker's sample
  std::int64_t run_id = 0, seq = 0;
  double t = 0;
  domain::ShakerSample v;
  std::int64_t status = 0;
};

struct Bucket {  // min/max of one stretch of a run: no peak is lost by decimation
  double t_min = 0, t_max = 0, disp_min = 0, disp_max = 0, force_min = 0, force_max = 0;
  std::int64_t n = 0;
};

struct CampaignRow {
  std::int64_t id = 0, rig_id = 0;
  domain::CampaignKind kind = domain::CampaignKind::fot;
  std::string plan;
  domain::CampaignState state = domain::CampaignState::queued;
  std::string created_at, updated_at;
};

struct EventRow {
  std::int64_t id = 0;
  std::string at, kind, from_state, to_state, detail;
};

// One daemon's records, read. Not for sharing between threads (each source is one connection).
class ReadSource {
 public:
  ReadSource() = default;
  ReadSource(const ReadSource&) = delete;
  ReadSource& operator=(const ReadSource&) = delete;
  virtual ~ReadSource() = default;

  [[nodiscard]] virtual std::optional<CampaignRow> campaign(std::int64_t id) = 0;
  [[nodiscard]] virtual std::vector<CampaignRow> campaigns() = 0;
  [[nodiscard]] virtual std::vector<EventRow> events(std::int64_t campaign_id) = 0;
  // Details of a campaign's events of one kind, oldest first.
  [[nodiscard]] virtual std::vector<std::string> event_details(std::int64_t campaign_id, const std::string& kind) = 0;
  // Why the campaign is in `state`: the reason of its newest transition there ("" when none).
  [[nodiscard]] virtual std::string state_reason(std::int64_t campaign_id, domain::CampaignState state) = 0;
  [[nodiscard]] virtual std::string rig_name(std::int64_t rig_id) = 0;
  // The rig's name and its config as hystlabd stored it ({"", "{}"} for no such rig).
  [[nodiscard]] virtual std::pair<std::string, std::string> rig_record(std::int64_t rig_id) = 0;
  [[nodiscard]] virtual std::vector<std::pair<std::int64_t, std::string>> rigs() = 0;  // id, name

  [[nodiscard]] virtual std::optional<RunInfo> run(std::int64_t id) = 0;
  [[nodiscard]] virtual std::vector<RunInfo> runs(std::int64_t campaign_id) = 0;
  // Every run of the campaign, or those of one role.
  [[nodiscard]] virtual std::vector<std::int64_t> runs_of_campaign(std::int64_t campaign_id, std::optional<domain::RunRole> role = std::nullopt) = 0;
  [[nodiscard]] virtual std::optional<std::pair<double, double>> time_span(std::int64_t run_id) = 0;  // rig seconds
  [[nodiscard]] virtual std::int64_t sample_count(std::int64_t run_id) = 0;
  [[nodiscard]] virtual std::int64_t max_seq(std::int64_t run_id) = 0;         // -1 when none
  [[nodiscard]] virtual std::int64_t max_shaker_seq(std::int64_t run_id) = 0;  // -1 when none
  // Decimated overview of [t0, t1] in at most `buckets` buckets of time, every peak kept. A
  // shaker run's buckets hold base (disp_*) and mass (force_*) displacement.
  [[nodiscard]] virtual std::vector<Bucket> overview(std::int64_t run_id, double t0, double t1, int buckets, bool shaker = false) = 0;
  virtual void for_each_sample(std::int64_t run_id, std::int64_t seq0, std::int64_t seq1, const std::function<void(const SampleRow&)>& f) = 0;
  virtual void for_each_shaker_sample(std::int64_t run_id, std::int64_t seq0, std::int64_t seq1, const std::function<void(const ShakerRow&)>& f) = 0;
  // Appends two columns of a run's samples from seq0 on, in order, as floats (plots):
  // displacement and force, or (base_mass) the command (base) and displacement (mass).
  // Returns the next seq to read.
  virtual std::int64_t read_xy(std::int64_t run_id, std::int64_t seq0, bool base_mass, std::vector<float>& x, std::vector<float>& y) = 0;

  [[nodiscard]] virtual std::int64_t table_count(std::int64_t campaign_id) = 0;
  [[nodiscard]] virtual std::vector<TableInfo> tables(std::optional<std::int64_t> campaign_id = std::nullopt) = 0;
  [[nodiscard]] virtual std::optional<TableInfo> table(std::int64_t id) = 0;
  [[nodiscard]] virtual std::optional<std::string> table_document(std::int64_t id) = 0;
  // The newest table of this method from a campaign of this rig (or of this campaign).
  [[nodiscard]] virtual std::optional<TableInfo> newest_table_of_rig(std::int64_t rig_id, const std::string& method) = 0;
  [[nodiscard]] virtual std::optional<TableInfo> newest_table_of_campaign(std::int64_t campaign_id, const std::string& method) = 0;
  [[nodiscard]] virtual std::vector<NodeInfo> nodes(std::int64_t campaign_id) = 0;
  [[nodiscard]] virtual std::vector<std::tuple<double, double, double, double>> fot_nodes_of_campaign(std::int64_t campaign_id) = 0;
  [[nodiscard]] virtual std::vector<TransmissibilityInfo> transmissibility(std::int64_t campaign_id) = 0;
  [[nodiscard]] virtual std::vector<LoopInfo> loops(std::int64_t campaign_id) = 0;  // every run's, by run and order of closing
};

}  // namespace hystlab::db
