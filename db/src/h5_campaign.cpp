// A campaign's context in a run's HDF5 file: what was planned, on which rig under which envelope,
// what happened (events), and the FOT nodes measured. JSON stays JSON text (plan, rig config,
// event details): the file carries it as the store has it.
#include <nlohmann/json.hpp>

#include <tuple>
#include <vector>

#include "h5_file.hpp"
#include "h5_layout.hpp"
#include "hystlab/db/campaign_record.hpp"
#include "hystlab/db/run_h5.hpp"
#include "hystlab/db/store.hpp"
#include "hystlab/models/sweep_analysis.hpp"

namespace hystlab::db::h5_layout {
namespace {
using h5::Handle;

// The envelope the campaign ran under: its newest "envelope" event (the rig's envelope as the
// daemon had it when it started the campaign: the rig's row holds only today's config, rewritten
// at every start of hystlabd), else the envelope the rig's stored config names; "null" when neither.
std::string envelope_in_force(ReadSource& store, std::int64_t campaign, const std::string& config) {
  if (const auto recorded = store.event_details(campaign, "envelope"); !recorded.empty()) {
    const auto e = nlohmann::json::parse(recorded.back(), nullptr, false);
    if (e.is_object()) return e.dump();
  }
  const auto j = nlohmann::json::parse(config, nullptr, false);
  return j.is_object() && j.contains("envelope") && j["envelope"].is_object() ? j["envelope"].dump() : "null";
}

void write_campaign_group(ReadSource& store, hid_t file, const CampaignRow& c) {
  const Handle g = h5::create_group(file, "campaign");
  h5::attr_int(g.get(), "id", c.id);
  h5::attr_text(g.get(), "kind", to_string(c.kind));
  h5::attr_text(g.get(), "state", to_string(c.state));
  h5::attr_text(g.get(), "created_at", c.created_at);
  h5::attr_text(g.get(), "updated_at", c.updated_at);
  // What the lab recorded with it (at submission or since: db/campaign_record.hpp).
  const CampaignRecord record = campaign_record(store, c);
  h5::attr_text(g.get(), "specimen", record.specimen);
  h5::attr_text(g.get(), "notes", record.notes);
  const auto [rig, config] = store.rig_record(c.rig_id);
  h5::attr_text(g.get(), "rig", rig);
  h5::dataset_text(g.get(), "plan", c.plan);
  h5::dataset_text(g.get(), "rig_config", config);
  h5::dataset_text(g.get(), "envelope", envelope_in_force(store, c.id, config));
  // The limits the campaign ran under (the envelope tightened by the plan's limits), as it recorded them.
  const auto limits = store.event_details(c.id, "limits");
  h5::dataset_text(g.get(), "limits", limits.empty() ? "null" : limits.back());
}

void write_events(ReadSource& store, hid_t file, std::int64_t campaign, int deflate_level) {
  const Handle g = h5::create_group(file, "events");
  std::vector<std::int64_t> id;
  std::vector<std::string> at, kind, from, to, detail;
  for (EventRow& e : store.events(campaign)) {
    id.push_back(e.id), at.push_back(std::move(e.at)), kind.push_back(std::move(e.kind));
    from.push_back(std::move(e.from_state)), to.push_back(std::move(e.to_state)), detail.push_back(std::move(e.detail));
  }
  (void)h5::write_column(g.get(), "id", std::span<const std::int64_t>(id), deflate_level);
  h5::dataset_texts(g.get(), "at", at, deflate_level);
  h5::dataset_texts(g.get(), "kind", kind, deflate_level);
  h5::dataset_texts(g.get(), "from_state", from, deflate_level);
  h5::dataset_texts(g.get(), "to_state", to, deflate_level);
  h5::dataset_texts(g.get(), "detail", detail, deflate_level);
}

void write_nodes(ReadSource& store, hid_t file, std::int64_t campaign, int deflate_level) {
  const Handle g = h5::create_group(file, "fot_nodes");
  std::vector<std::int64_t> id, run;
  std::vector<double> alpha, beta, fa, fab, t;
  for (const NodeInfo& n : store.nodes(campaign)) {
    id.push_back(n.id), run.push_back(n.run), alpha.push_back(n.alpha), beta.push_back(n.beta);
    fa.push_back(n.force_alpha), fab.push_back(n.force_alpha_beta), t.push_back(n.t);
  }
  (void)h5::write_column(g.get(), "id", std::span<const std::int64_t>(id), deflate_level);
  (void)h5::write_column(g.get(), "run", std::span<const std::int64_t>(run), deflate_level);
  const std::pair<const char*, const std::vector<double>*> cols[] = {
      {"alpha_mm", &alpha}, {"beta_mm", &beta}, {"force_alpha_N", &fa}, {"force_alpha_beta_N", &fab}, {"time_s", &t}};
  for (const auto& [name, v] : cols) {
    const Handle d = h5::write_column(g.get(), name, std::span<const double>(*v), deflate_level);
    const std::string n = name;
    h5::attr_text(d.get(), "units", n.substr(n.rfind('_') + 1));
  }
}
// A sine campaign's points, one row per step measured, as GET /api/campaigns/ID/sweep.csv has
// them: with each step's equivalent damping from its hysteresis loop (models/sweep_analysis.hpp),
// measured and predicted (NaN without a prediction). None for a campaign without points.
void write_sweep(ReadSource& store, hid_t file, std::int64_t campaign, int deflate_level) {
  const auto rows = store.transmissibility(campaign);
  if (rows.empty()) return;
  const Handle g = h5::create_group(file, "sweep");
  std::vector<std::int64_t> step, run;
  std::vector<std::string> direction;
  std::vector<double> f, demand, base, mass, ratio, phase, pratio, pphase, zeta, pzeta;
  for (const TransmissibilityInfo& t : rows) {
    step.push_back(t.step), run.push_back(t.run), direction.push_back(t.direction.empty() ? "up" : t.direction);
    f.push_back(t.frequency_hz), demand.push_back(t.demand_mm), base.push_back(t.base_amplitude_mm), mass.push_back(t.mass_amplitude_mm);
    ratio.push_back(t.ratio), phase.push_back(t.phase_rad), pratio.push_back(t.predicted_ratio), pphase.push_back(t.predicted_phase_rad);
    zeta.push_back(models::equivalent_damping(t.ratio, t.phase_rad)), pzeta.push_back(models::equivalent_damping(t.predicted_ratio, t.predicted_phase_rad));
  }
  (void)h5::write_column(g.get(), "step", std::span<const std::int64_t>(step), deflate_level);
  (void)h5::write_column(g.get(), "run", std::span<const std::int64_t>(run), deflate_level);
  h5::dataset_texts(g.get(), "direction", direction, deflate_level);
  const std::tuple<const char*, const std::vector<double>*, const char*> cols[] = {{"frequency_hz", &f, "Hz"},
                                                                                   {"amplitude_mm", &demand, "mm"},
                                                                                   {"base_amplitude_mm", &base, "mm"},
                                                                                   {"mass_amplitude_mm", &mass, "mm"},
                                                                                   {"ratio", &ratio, "1"},
                                                                                   {"phase_rad", &phase, "rad"},
                                                                                   {"predicted_ratio", &pratio, "1"},
                                                                                   {"predicted_phase_rad", &pphase, "rad"},
                                                                                   {"equivalent_damping", &zeta, "1"},
                                                                                   {"predicted_equivalent_damping", &pzeta, "1"}};
  for (const auto& [name, v, units] : cols) {
    const Handle d = h5::write_column(g.get(), name, std::span<const double>(*v), deflate_level);
    h5::attr_text(d.get(), "units", units);
  }
}
}  // namespace

std::int64_t write_campaign(ReadSource& store, hid_t file, std::int64_t campaign, int deflate_level) {
  const auto c = store.campaign(campaign);
  if (!c) throw H5ExportError(H5ExportError::Kind::not_found, "no campaign " + std::to_string(campaign));
  write_campaign_group(store, file, *c);
  write_events(store, file, campaign, deflate_level);
  write_nodes(store, file, campaign, deflate_level);
  write_sweep(store, file, campaign, deflate_level);
  return write_tables(store, file, campaign, deflate_level);
}

}  // namespace hystlab::db::h5_layout
