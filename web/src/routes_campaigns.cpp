// Campaigns: submit, list, get, commands; their events, FOT nodes (coverage) and runs.
#include <algorithm>

#include "hystlab/db/campaign_record.hpp"
#include "hystlab/domain/plan.hpp"
#include "hystlab/models/adaptive_fot.hpp"
#include "hystlab/models/online_table_builder.hpp"
#include "request_guard.hpp"
#include "routes.hpp"

namespace hystlab::web {
db::CampaignRow campaign_or_404(db::ReadSource& store, std::int64_t id) {
  auto row = store.campaign(id);
  if (!row) throw ApiError(404, "not found", "no campaign " + std::to_string(id));
  return *row;
}

json runs_of(db::ReadSource& store, std::int64_t campaign) {
  json runs = json::array();
  for (const db::RunInfo& r : store.runs(campaign))
    runs.push_back({{"id", r.id},
                    {"role", r.role},
                    {"state", r.state},
                    {"started_at", r.started_at},
                    {"ended_at", r.ended_at},
                    {"samples", r.samples},
                    {"nodes", r.nodes},
                    {"quality", run_quality(store, campaign, r.id)}});
  return runs;
}

namespace {

// Each table with the warnings of the run it was computed over (the campaign's last).
json tables_of(db::ReadSource& store, std::int64_t campaign, const json& runs) {
  json out = json::array();
  for (const db::TableInfo& t : store.tables(campaign)) {
    json j = table_json(t);
    json warnings = json::array();
    for (const json& r : runs)
      for (const json& w : result_warnings(r["quality"])) warnings.push_back(w);
    j["warnings"] = warnings;
    // A least-squares table's prior and regularisation, as fields (not only inside a sentence).
    if (t.method == "lsq")
      if (const auto text = store.table_document(t.id)) {
        const json doc = json::parse(*text, nullptr, false);
        const json details = doc.is_object() ? doc.value("provenance", json::object()).value("details", json::object()) : json::object();
        if (details.is_object() && details.contains("prior")) j["prior"] = details["prior"], j["lambda"] = details.value("lambda", json());
        if (details.is_object() && details.contains("reason")) j["prior_reason"] = details["reason"];
      }
    out.push_back(j);
  }
  return out;
}

// The newest online evaluation of the partial table ("fit" event), if any.
json last_fit(db::ReadSource& store, std::int64_t campaign) {
  const auto fits = db::events_of<domain::FitEvent>(store, campaign);
  return fits.empty() ? json(nullptr) : domain::detail_json(fits.back());
}

}  // namespace

json nodes_json(db::ReadSource& store, const db::CampaignRow& row) {
  const std::vector<db::NodeInfo> measured = store.nodes(row.id);
  json out{{"campaign", row.id}, {"nodes", json::array()}};
  if (row.kind != domain::CampaignKind::fot) {
    for (const db::NodeInfo& n : measured) out["nodes"].push_back(node_json(n));
    return out;
  }
  // The stored plan through the one parser; the coverage counted by the table builder the daemon
  // fits with (a resumed campaign's node measured twice counts once), at the daemon's snapping.
  const domain::Plan plan = domain::parse_plan(json::parse(row.plan));
  const models::Grid fine = domain::node_grid(plan);
  models::OnlineTableBuilder builder(fine, 0.25 * fine.step());
  for (const db::NodeInfo& n : measured) (void)builder.add({n.alpha, n.beta, n.force_alpha, n.force_alpha_beta});
  if (plan.design.adaptive) {  // the table is the rows measured whole (their own grid); the design's steps
    if (std::optional<models::OnlineTableBuilder> rows = models::rows_builder(builder)) builder = std::move(*rows);
    json steps = json::array();
    for (const domain::DesignEvent& e : db::events_of<domain::DesignEvent>(store, row.id)) steps.push_back(domain::detail_json(e));
    out["design"] = {{"finest_subdivisions", fine.n}, {"budget_s", plan.design.budget_s}, {"target_rms_N", plan.design.target_rms_N}, {"steps", steps}};
  }
  const models::Grid& g = builder.grid();
  // An adaptive campaign's nodes of its table only: those between its rows wait for a row there.
  const double tol = 1e-6 * (g.hi - g.lo);
  for (const db::NodeInfo& n : measured)
    if (!plan.design.adaptive || (g.node_near(n.alpha, tol) >= 0 && g.node_near(n.beta, tol) >= 0)) out["nodes"].push_back(node_json(n));
  out["grid"] = {{"n", g.n}, {"lo_mm", g.lo}, {"hi_mm", g.hi}, {"nodes_mm", g.nodes()}};
  out["identified"] = builder.identified_nodes();
  out["required"] = builder.required_nodes();
  out["coverage"] = static_cast<double>(builder.identified_nodes()) / static_cast<double>(builder.required_nodes());
  return out;
}

json events_json(db::ReadSource& store, std::int64_t campaign) {
  json out = json::array();
  for (const auto& e : store.events(campaign))
    out.push_back({{"id", e.id}, {"at", e.at}, {"kind", e.kind}, {"from", e.from_state}, {"to", e.to_state}, {"detail", event_detail(e.kind, e.detail)}});
  return out;
}

json loops_json(db::ReadSource& store, std::int64_t campaign) {
  json out = json::array();
  for (const db::LoopInfo& l : store.loops(campaign)) {
    json j = parse_or_text(l.figures_json);
    if (!j.is_object()) continue;
    j["run"] = l.run;
    j["k"] = l.k;
    j["phase"] = l.phase;
    out.push_back(std::move(j));
  }
  return out;
}

json campaign_json(db::ReadSource& store, const db::CampaignRow& row, bool details) {
  json j{{"id", row.id},
         {"rig", store.rig_name(row.rig_id)},
         {"kind", domain::to_string(row.kind)},
         {"state", domain::to_string(row.state)},
         {"created_at", row.created_at},
         {"updated_at", row.updated_at}};
  // What the state means, so that a page needs no list of states of its own.
  json commands = json::array();
  for (const control::CampaignCommand cmd : control::commands_for(row.state)) commands.push_back(domain::to_string(cmd));
  j["commands"] = commands;
  j["active"] = domain::is_active(row.state);
  j["final"] = domain::is_final(row.state);
  // What the lab records with it: at submission, or changed since (POST .../record).
  const db::CampaignRecord record = db::campaign_record(store, row);
  j["specimen"] = record.specimen.empty() ? json(nullptr) : json(record.specimen);
  j["notes"] = record.notes.empty() ? json(nullptr) : json(record.notes);
  j["record_changed_at"] = record.changed_at.empty() ? json(nullptr) : json(record.changed_at);
  // Why it is in this state (why it ended, was held, failed), beside the state wherever it is shown.
  const std::string why = store.state_reason(row.id, row.state);
  j["reason"] = why.empty() ? json(nullptr) : json(why);
  if (!details) {
    j["tables"] = store.table_count(row.id);
    return j;
  }
  j["plan"] = parse_or_text(row.plan);
  j["runs"] = runs_of(store, row.id);
  j["tables"] = tables_of(store, row.id, j["runs"]);
  j["fit"] = last_fit(store, row.id);
  // Training (each cycle's figures: the shakedown curve, and what it came to) and the table the
  // campaign recommends, with the reason.
  json shakedown = json::array();
  for (const domain::ShakedownEvent& cycle : db::events_of<domain::ShakedownEvent>(store, row.id)) shakedown.push_back(domain::detail_json(cycle));
  j["shakedown"] = shakedown;
  const auto training = db::events_of<domain::TrainingEvent>(store, row.id);
  j["training"] = training.empty() ? json(nullptr) : domain::detail_json(training.back());
  const auto rec = db::events_of<domain::RecommendationEvent>(store, row.id);
  j["recommendation"] = rec.empty() ? json(nullptr) : domain::detail_json(rec.back());
  if (row.kind == domain::CampaignKind::fot) {
    const json nodes = nodes_json(store, row);
    j["progress"] = {{"nodes", nodes["identified"]}, {"required", nodes["required"]}};
    if (nodes.contains("design")) j["design"] = nodes["design"];  // an adaptive campaign's steps: the page's design panel
  }
  return j;
}

void add_campaign_routes(httplib::Server& s, ApiContext& c) {
  post_route(s, c, "/api/campaigns", guarded([&c](const httplib::Request& req, httplib::Response& res) {
               const PlanRequest r = decode_plan_request(body_object(req));
               const std::int64_t id = c.daemon.submit(r.rig, r.plan);
               res.set_header("Location", "/api/campaigns/" + std::to_string(id));
               send_json(res, campaign_json(reader(c.db_path), campaign_or_404(reader(c.db_path), id), false), 201);
             }));
  // The specimen and notes, changed after submission (any state): {"specimen": ..., "notes": ...}.
  post_route(s, c, R"(/api/campaigns/(\d+)/record)", guarded([&c](const httplib::Request& req, httplib::Response& res) {
               const auto row = campaign_or_404(reader(c.db_path), path_id(req));
               try {
                 c.daemon.set_record(row.id, body_object(req));
               } catch (const control::PlanError& e) {  // not a plan's field: named as the body's
                 throw ApiError(400, "invalid record", e.what(), e.field);
               } catch (const std::out_of_range& e) {
                 throw ApiError(404, "not found", e.what());
               }
               auto& store = reader(c.db_path);
               send_json(res, campaign_json(store, campaign_or_404(store, row.id), false));
             }));
  post_route(s, c, R"(/api/campaigns/(\d+)/([a-z_]+))", guarded([&c](const httplib::Request& req, httplib::Response& res) {
               const std::string verb = req.matches[2].str();
               const auto cmd = control::campaign_command_from(verb);
               if (!cmd) throw ApiError(404, "not found", "no command '" + verb + "' for a campaign (pause, resume, abort, estop)");
               auto& store = reader(c.db_path);
               const auto row = campaign_or_404(store, path_id(req));
               const auto applies = control::commands_for(row.state);
               if (std::find(applies.begin(), applies.end(), *cmd) == applies.end()) {
                 std::string which;
                 for (const auto a : applies) which += std::string(which.empty() ? "" : ", ") + domain::to_string(a);
                 throw ApiError(409, "conflict",
                                "campaign " + std::to_string(row.id) + " is " + domain::to_string(row.state) + ": '" + verb + "' does not apply" +
                                    (which.empty() ? std::string() : " (" + which + " do)"));
               }
               send_outcome(res, json{{"campaign", row.id}, {"command", verb}}, c.daemon.command(row.id, *cmd));
             }));
}

}  // namespace hystlab::web
