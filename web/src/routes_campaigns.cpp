// Campaigns: submit, list, get, commands; their events, FOT nodes (coverage), runs and
// transmissibility.
#include <set>

#include "hystlab/daemon/plan.hpp"
#include "hystlab/db/sqlite.hpp"
#include "hystlab/models/grid.hpp"
#include "routes.hpp"

namespace hystlab::web {
namespace {
json parse_or_text(const std::string& s) {
  if (s.empty()) return nullptr;
  const json j = json::parse(s, nullptr, false);
  return j.is_discarded() ? json(s) : j;
}

db::CampaignRow campaign_or_404(db::Store& store, std::int64_t id) {
  auto row = store.campaign(id);
  if (!row) throw ApiError(404, "not found", "no campaign " + std::to_string(id));
  return *row;
}

std::string rig_name(db::Store& store, std::int64_t rig_id) {
  db::Statement st(store.database(), "SELECT name FROM rigs WHERE id = ?");
  st.bind(1, rig_id);
  return st.step() ? st.column_text(0) : std::string();
}

json runs_of(db::Store& store, std::int64_t campaign) {
  json runs = json::array();
  db::Statement st(store.database(),
                   "SELECT id, state, started_at, coalesce(ended_at, ''), (SELECT coalesce(sum(n), 0) FROM sample_blocks WHERE run_id = runs.id), "
                   "(SELECT count(*) FROM fot_nodes WHERE run_id = runs.id) FROM runs WHERE campaign_id = ? ORDER BY id");
  st.bind(1, campaign);
  while (st.step())
    runs.push_back({{"id", st.column_int(0)}, {"state", st.column_text(1)}, {"started_at", st.column_text(2)},
                    {"ended_at", st.column_text(3)}, {"samples", st.column_int(4)}, {"nodes", st.column_int(5)}});
  return runs;
}

json tables_of(db::Store& store, std::int64_t campaign) {
  json out = json::array();
  db::Statement st(store.database(), kTableSelect +
                                     "WHERE campaign_id = ? ORDER BY id");
  st.bind(1, campaign);
  while (st.step()) out.push_back(table_row_json(st));
  return out;
}

// The newest online evaluation of the partial table ("fit" event), if any.
json last_fit(db::Store& store, std::int64_t campaign) {
  db::Statement st(store.database(), "SELECT detail FROM events WHERE campaign_id = ? AND kind = 'fit' ORDER BY id DESC LIMIT 1");
  st.bind(1, campaign);
  return st.step() ? parse_or_text(st.column_text(0)) : json(nullptr);
}

json nodes_json(db::Store& store, const db::CampaignRow& row) {
  json nodes = json::array();
  db::Statement st(store.database(), kNodeSelect +
                                     "WHERE r.campaign_id = ? ORDER BY f.id");
  st.bind(1, row.id);
  while (st.step()) nodes.push_back(node_json(st));
  json out{{"campaign", row.id}, {"nodes", nodes}};
  if (row.kind != "fot") return out;
  const daemon::Plan plan = daemon::parse_plan(json::parse(row.plan));
  const models::Grid g = models::Grid::make(plan.lo_mm, plan.hi_mm, plan.subdivisions);
  std::set<std::pair<int, int>> seen;  // a resumed campaign may measure a node twice
  const double tol = 0.25 * g.step();
  for (const json& n : nodes) {
    const int i = g.node_near(n["alpha"].get<double>(), tol), j = g.node_near(n["beta"].get<double>(), tol);
    if (i > 0 && j >= 0 && j < i) seen.insert({i, j});
  }
  const std::size_t required = static_cast<std::size_t>(g.n) * static_cast<std::size_t>(g.n + 1) / 2;
  out["grid"] = {{"n", g.n}, {"lo_mm", g.lo}, {"hi_mm", g.hi}};
  out["identified"] = seen.size();
  out["required"] = required;
  out["coverage"] = static_cast<double>(seen.size()) / static_cast<double>(required);
  return out;
}
}  // namespace

json node_json(db::Statement& st) {
  const double fa = st.column_double(5), fab = st.column_double(6);
  return {{"id", st.column_int(0)}, {"campaign", st.column_int(1)}, {"run", st.column_int(2)}, {"alpha", st.column_double(3)},
          {"beta", st.column_double(4)}, {"force_alpha", fa}, {"force_alpha_beta", fab}, {"F", fa - fab}, {"t", st.column_double(7)}};
}

json table_row_json(db::Statement& st) {
  return {{"id", st.column_int(0)},
          {"campaign", st.column_is_null(1) ? json(nullptr) : json(st.column_int(1))},
          {"run", st.column_is_null(2) ? json(nullptr) : json(st.column_int(2))},
          {"method", st.column_text(3)}, {"n", st.column_int(4)}, {"range_mm", {st.column_double(5), st.column_double(6)}},
          {"created_at", st.column_text(7)}, {"accuracy", parse_or_text(st.column_text(8))}};
}

json campaign_json(db::Store& store, const db::CampaignRow& row, bool details) {
  json j{{"id", row.id}, {"rig", rig_name(store, row.rig_id)}, {"kind", row.kind}, {"state", row.state},
         {"created_at", row.created_at}, {"updated_at", row.updated_at}};
  if (!details) {
    db::Statement st(store.database(), "SELECT count(*) FROM tables WHERE campaign_id = ?");
    st.bind(1, row.id);
    st.step();
    j["tables"] = st.column_int(0);
    return j;
  }
  j["plan"] = parse_or_text(row.plan);
  j["runs"] = runs_of(store, row.id);
  j["tables"] = tables_of(store, row.id);
  j["fit"] = last_fit(store, row.id);
  if (row.kind == "fot") {
    const json nodes = nodes_json(store, row);
    j["progress"] = {{"nodes", nodes["identified"]}, {"required", nodes["required"]}};
  }
  return j;
}

void add_campaign_routes(httplib::Server& s, ApiContext& c) {
  s.Get("/api/campaigns", guarded([&c](const httplib::Request& req, httplib::Response& res) {
    auto& store = reader(c.db_path);
    const std::string state = req.has_param("state") ? req.get_param_value("state") : "";
    json out = json::array();
    for (const auto& row : store.campaigns())
      if (state.empty() || row.state == state) out.push_back(campaign_json(store, row, false));
    send_json(res, out);
  }));
  s.Post("/api/campaigns", guarded([&c](const httplib::Request& req, httplib::Response& res) {
    const json body = body_object(req);
    for (const auto& [k, _] : body.items())
      if (k != "plan" && k != "rig") throw ApiError(400, "invalid request", k + ": not a known field (plan, rig)");
    if (!body.contains("plan") || !body["plan"].is_object()) throw ApiError(400, "invalid request", "plan: must be a JSON object (a campaign plan)");
    if (body.contains("rig") && !body["rig"].is_string()) throw ApiError(400, "invalid request", "rig: must be a rig's name");
    const std::int64_t id = c.daemon.submit(body.value("rig", std::string()), body["plan"]);
    res.set_header("Location", "/api/campaigns/" + std::to_string(id));
    send_json(res, campaign_json(reader(c.db_path), campaign_or_404(reader(c.db_path), id), false), 201);
  }));
  s.Get(R"(/api/campaigns/(\d+))", guarded([&c](const httplib::Request& req, httplib::Response& res) {
    auto& store = reader(c.db_path);
    send_json(res, campaign_json(store, campaign_or_404(store, path_id(req)), true));
  }));
  s.Post(R"(/api/campaigns/(\d+)/(pause|resume|abort|estop))", guarded([&c](const httplib::Request& req, httplib::Response& res) {
    auto& store = reader(c.db_path);
    const auto row = campaign_or_404(store, path_id(req));
    const std::string verb = req.matches[2].str();
    static const std::set<std::string> ended{"completed", "aborted", "failed"};
    if (ended.count(row.state))
      throw ApiError(409, "conflict", "campaign " + std::to_string(row.id) + " is " + row.state + ": '" + verb + "' does not apply");
    c.daemon.command(row.id, verb);
    send_json(res, json{{"campaign", row.id}, {"command", verb}, {"accepted", true}, {"state", row.state}}, 202);
  }));
  s.Get(R"(/api/campaigns/(\d+)/events)", guarded([&c](const httplib::Request& req, httplib::Response& res) {
    auto& store = reader(c.db_path);
    const auto row = campaign_or_404(store, path_id(req));
    json out = json::array();
    for (const auto& e : store.events(row.id))
      out.push_back({{"id", e.id}, {"at", e.at}, {"kind", e.kind}, {"from", e.from_state}, {"to", e.to_state}, {"detail", parse_or_text(e.detail)}});
    send_json(res, out);
  }));
  s.Get(R"(/api/campaigns/(\d+)/nodes)", guarded([&c](const httplib::Request& req, httplib::Response& res) {
    auto& store = reader(c.db_path);
    send_json(res, nodes_json(store, campaign_or_404(store, path_id(req))));
  }));
  s.Get(R"(/api/campaigns/(\d+)/runs)", guarded([&c](const httplib::Request& req, httplib::Response& res) {
    auto& store = reader(c.db_path);
    send_json(res, runs_of(store, campaign_or_404(store, path_id(req)).id));
  }));
  s.Get(R"(/api/campaigns/(\d+)/transmissibility)", guarded([&c](const httplib::Request& req, httplib::Response& res) {
    auto& store = reader(c.db_path);
    const auto row = campaign_or_404(store, path_id(req));
    json out = json::array();
    db::Statement st(store.database(), "SELECT t.id, t.run_id, frequency_hz, base_amplitude_mm, mass_amplitude_mm, ratio, phase_rad "
                                       "FROM transmissibility t JOIN runs r ON r.id = t.run_id WHERE r.campaign_id = ? ORDER BY t.id");
    st.bind(1, row.id);
    while (st.step())
      out.push_back({{"id", st.column_int(0)}, {"run", st.column_int(1)}, {"frequency_hz", st.column_double(2)},
                     {"base_amplitude_mm", st.column_double(3)}, {"mass_amplitude_mm", st.column_double(4)},
                     {"ratio", st.column_double(5)}, {"phase_rad", st.column_double(6)}});
    send_json(res, out);
  }));
}

}  // namespace hystlab::web
