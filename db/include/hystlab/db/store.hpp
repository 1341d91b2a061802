#pragma once
// The hystlab store: one SQLite file holding rigs, campaigns with their events, runs, samples,
// FOT nodes, tables and I/O statistics. One Store per thread (WAL: readers never block the writer).
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <variant>
#include <vector>

#include "hystlab/db/reads.hpp"
#include "hystlab/db/sqlite.hpp"
#include "hystlab/domain/campaign.hpp"
#include "hystlab/domain/events.hpp"
#include "hystlab/domain/signals.hpp"

namespace hystlab::db {

inline constexpr std::int64_t kBlockSize = 1024;  // samples per summary block

using AnyRow = std::variant<SampleRow, ShakerRow>;

// Bumped after every committed change of the records the API streams (campaigns and their
// events, FOT nodes, tables, transmissibility) made through a Store of this process: event
// streams read the database only when it moved (or now and then, for other processes' writes).
[[nodiscard]] std::uint64_t record_generation() noexcept;

// The store is split by concern; a Store is all three on one connection. A part that only
// reads (the API's routes, the CLI's views, exports) takes a ReadSource& (reads.hpp): it cannot write, and the lab database can answer it too.
//   Reads      every query (store_reads.cpp, store.cpp's sample reads)
//   Writes     what a running campaign produces, row by row: samples (the writer thread), FOT
//              nodes, sine points (store.cpp)
//   Lifecycle  rigs, campaigns, runs, events and their state changes, tables and the finishing
//              of a run, each in one transaction (store_lifecycle.cpp)
class Reads : public ReadSource {
 public:
  explicit Reads(Database& db) noexcept : db_(db) {}
  [[nodiscard]] std::int64_t table_count(std::int64_t campaign_id) override;
  // Every run of the campaign, or those of one role.
  [[nodiscard]] std::vector<std::int64_t> runs_of_campaign(std::int64_t campaign_id, std::optional<domain::RunRole> role = std::nullopt) override;
  [[nodiscard]] std::vector<std::string> rig_names();
  [[nodiscard]] std::vector<std::int64_t> queued_campaigns(std::int64_t rig_id);
  [[nodiscard]] std::vector<std::tuple<double, double, double, double>> fot_nodes_of_campaign(std::int64_t campaign_id) override;

  [[nodiscard]] std::optional<CampaignRow> campaign(std::int64_t id) override;
  [[nodiscard]] std::vector<CampaignRow> campaigns() override;
  [[nodiscard]] std::vector<EventRow> events(std::int64_t campaign_id) override;
  [[nodiscard]] std::int64_t sample_count(std::int64_t run_id) override;
  [[nodiscard]] std::int64_t max_seq(std::int64_t run_id) override;  // -1 when none
  // Decimated overview of [t0, t1] in at most `buckets` buckets (blocks when the range is long,
  // raw samples when it is short).
  // A shaker run's buckets hold base (disp_*) and mass (force_*) displacement.
  [[nodiscard]] std::vector<Bucket> overview(std::int64_t run_id, double t0, double t1, int buckets, bool shaker = false) override;
  void for_each_sample(std::int64_t run_id, std::int64_t seq0, std::int64_t seq1, const std::function<void(const SampleRow&)>& f) override;
  void for_each_shaker_sample(std::int64_t run_id, std::int64_t seq0, std::int64_t seq1, const std::function<void(const ShakerRow&)>& f) override;
  [[nodiscard]] std::int64_t max_shaker_seq(std::int64_t run_id) override;  // -1 when none
  [[nodiscard]] std::string integrity_check();

  [[nodiscard]] std::string rig_name(std::int64_t rig_id) override;
  // The rig's name and its config as hystlabd stored it ({"", "{}"} for no such rig).
  [[nodiscard]] std::pair<std::string, std::string> rig_record(std::int64_t rig_id) override;
  [[nodiscard]] std::vector<std::pair<std::int64_t, std::string>> rigs() override;              // id, name
  [[nodiscard]] std::vector<std::pair<domain::CampaignState, std::int64_t>> campaign_counts();  // by state
  [[nodiscard]] std::optional<RunInfo> run(std::int64_t id) override;
  [[nodiscard]] std::vector<RunInfo> runs(std::int64_t campaign_id) override;
  [[nodiscard]] std::optional<std::pair<double, double>> time_span(std::int64_t run_id) override;  // rig seconds
  [[nodiscard]] std::vector<TableInfo> tables(std::optional<std::int64_t> campaign_id = std::nullopt) override;
  [[nodiscard]] std::optional<TableInfo> table(std::int64_t id) override;
  [[nodiscard]] std::optional<std::string> table_document(std::int64_t id) override;
  // The newest table of this method from a campaign of this rig (or of this campaign).
  [[nodiscard]] std::optional<TableInfo> newest_table_of_rig(std::int64_t rig_id, const std::string& method) override;
  [[nodiscard]] std::optional<TableInfo> newest_table_of_campaign(std::int64_t campaign_id, const std::string& method) override;
  [[nodiscard]] std::vector<NodeInfo> nodes(std::int64_t campaign_id) override;
  [[nodiscard]] std::vector<TransmissibilityInfo> transmissibility(std::int64_t campaign_id) override;
  [[nodiscard]] std::vector<LoopInfo> loops(std::int64_t campaign_id) override;  // every run's, by run and order of closing
  // Details of a campaign's events of one kind, oldest first.
  [[nodiscard]] std::vector<std::string> event_details(std::int64_t campaign_id, const std::string& kind) override;
  // Why the campaign is in `state`: the reason of its newest transition there ("" when none).
  [[nodiscard]] std::string state_reason(std::int64_t campaign_id, domain::CampaignState state) override;
  // Records since an id, across campaigns, oldest first, at most limit (the event stream).
  [[nodiscard]] std::vector<EventInfo> events_after(std::int64_t id, int limit);
  [[nodiscard]] std::vector<NodeInfo> nodes_after(std::int64_t id, int limit);
  [[nodiscard]] std::vector<TableInfo> tables_after(std::int64_t id, int limit);
  [[nodiscard]] std::int64_t newest_id(const std::string& table);  // events, fot_nodes or tables
  // Appends two columns of a run's samples from seq0 on, in order, as floats (plots):
  // displacement and force, or (base_mass) the command (base) and displacement (mass).
  // Returns the next seq to read.
  std::int64_t read_xy(std::int64_t run_id, std::int64_t seq0, bool base_mass, std::vector<float>& x, std::vector<float>& y) override;

 protected:
  Database& db_;
};

class Writes {
 public:
  explicit Writes(Database& db);  // the database migrated
  std::int64_t add_transmissibility(std::int64_t run_id, double f_hz, double base_mm, double mass_mm, double ratio, double phase);
  std::int64_t add_fot_node(std::int64_t run_id, double alpha, double beta, double f_alpha, double f_alpha_beta, double t);
  // Inserts rows and their block summaries; the caller holds the transaction. A shaker run's
  // block summaries hold its base (disp_*) and mass (force_*) displacement: an index for overviews.
  void insert_samples(std::span<const SampleRow> rows);
  void insert_rows(std::span<const AnyRow> rows);

  // A sine step's result: the columns the sweep plots need, and the whole record as JSON.
  std::int64_t add_sine_point(std::int64_t run, const SinePointRow& p);
  void set_prediction(std::int64_t point_id, double ratio, double phase_rad);

 private:
  Database& db_;
  Statement insert_sample_, upsert_block_, insert_shaker_;
};

class Lifecycle {
 public:
  Lifecycle(Database& db, Reads& reads) noexcept : db_(db), reads_(reads) {}
  std::int64_t upsert_rig(const std::string& name, const std::string& config_json, const std::string& now);
  std::int64_t create_campaign(std::int64_t rig_id, domain::CampaignKind kind, const std::string& plan_json, const std::string& now);
  // Updates the state and records the transition as an event, in one transaction.
  void transition(std::int64_t campaign_id, domain::CampaignState to, const std::string& reason, const std::string& now);
  std::int64_t add_run(std::int64_t campaign_id, const std::string& now, double wall_anchor_unix, double monotonic_anchor_s,
                       domain::RunRole role = domain::RunRole::campaign);
  // The campaign's run and, when asked, its validation run (else 0), in one transaction.
  std::pair<std::int64_t, std::int64_t> add_runs(std::int64_t campaign_id, const std::string& now, double wall_anchor_unix, double monotonic_anchor_s,
                                                 bool validation);
  void end_run(std::int64_t run_id, domain::CampaignState state, const std::string& now);
  std::int64_t add_event(std::int64_t campaign_id, const domain::CampaignEvent& event, const std::string& now);
  // A detail as stored, of any kind: the tests of older or foreign details (the daemon writes typed events).
  std::int64_t add_raw_event(std::int64_t campaign_id, const std::string& kind, const std::string& detail, const std::string& now);
  std::int64_t add_table(std::optional<std::int64_t> campaign_id, std::optional<std::int64_t> run_id, const std::string& method, int n, double lo, double hi,
                         const std::string& now, const std::string& accuracy_json, const std::string& document_json);
  // At start-up: every campaign left arming, running or paused by a crash becomes interrupted,
  // except one whose tables were stored (finishing was done): that one is completed.
  int mark_interrupted(const std::string& now);
  // At start-up: campaigns left queued wait for an operator ('held'); nothing moves by itself.
  int hold_queued(const std::string& now);
  struct TableRecord {
    std::string method;
    int n = 0;
    double lo = 0, hi = 0;
    std::string accuracy_json, document_json;
  };
  struct LoopRecord {
    std::int64_t run = 0;
    int k = 0;
    domain::LoopPhase phase = domain::LoopPhase::rows;
    std::string figures_json;
  };
  struct RunEnd {
    std::int64_t campaign = 0, run = 0;
    std::int64_t validation_run = 0;  // 0: none; removed when it never took a sample
    std::vector<TableRecord> tables;
    std::vector<LoopRecord> loops;
    domain::CampaignState state = domain::CampaignState::completed;
    std::string reason, now;
    // The table the campaign recommends (an index into tables) and why: stored as a
    // "recommendation" event naming the new table's id, before the campaign's last state.
    std::optional<std::size_t> recommended;
    std::string recommendation;
    struct Prediction {
      std::int64_t step = 0;
      double ratio = 0, phase_rad = 0;
    };
    std::vector<Prediction> predictions;  // sine: beside the run's points of these step numbers
  };
  // Ends a run (and its validation run) and its campaign in one transaction: the tables, the loop
  // figures, the runs' state, the campaign's state with its transition event. When the campaign
  // already has tables (finishing again after a crash), none are added. Returns the new tables' ids.
  std::vector<std::int64_t> finish_run(const RunEnd& end);
  void add_io_stats(std::int64_t rig_id, const std::string& stats_json, const std::string& now);

 private:
  void transition_in(std::int64_t campaign_id, domain::CampaignState to, const std::string& reason, const std::string& now);
  Database& db_;
  Reads& reads_;
};

namespace detail {
struct OpenDatabase {  // opened and migrated before the parts that use it are built
  OpenDatabase(const std::string& path, bool synchronous_full);
  Database db;
};
}  // namespace detail

class Store : private detail::OpenDatabase, public Reads, public Writes, public Lifecycle {
 public:
  explicit Store(const std::string& path, bool synchronous_full = true);  // opens and migrates
  [[nodiscard]] Database& database() noexcept { return db; }
};

// A campaign's events of one kind, typed (domain/events.hpp), oldest first; those whose detail
// does not fit their type (written by another version) are left out.
template <class E>
std::vector<E> events_of(ReadSource& store, std::int64_t campaign) {
  std::vector<E> out;
  const std::string kind(domain::kind_of(E{}));
  std::string error;
  for (const std::string& text : store.event_details(campaign, kind))
    if (auto e = domain::decode_event(kind, text, error)) out.push_back(std::get<E>(std::move(*e)));
  return out;
}

}  // namespace hystlab::db
