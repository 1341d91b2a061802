// The read endpoints (read_routes.hpp), on whichever source the request names.
#include "read_routes.hpp"

#include <limits>
#include <vector>

#include "hystlab/fmu/element_export.hpp"
#include "hystlab/models/table_export.hpp"
#include "hystlab/models/table_score.hpp"
#include "routes.hpp"

namespace hystlab::web {
namespace {
// The id in the path: its last group (the lab view's prefix holds the daemon's name before it).
std::int64_t id_of(const httplib::Request& req) { return path_id(req, req.matches.size() - 1); }

using Get = std::function<void(const std::string&, const ReadHandler&)>;

void add_campaign_reads(const Get& get) {
  get("/api/campaigns", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    const std::string state = req.has_param("state") ? req.get_param_value("state") : "";
    if (!state.empty() && !domain::campaign_state_from(state)) {
      std::string known;
      for (const domain::CampaignState k : domain::kCampaignStates) known += (known.empty() ? "" : ", ") + std::string(domain::to_string(k));
      throw ApiError(400, "invalid parameter", "state: '" + state + "' is not a campaign state (" + known + ")", "state");
    }
    json out = json::array();
    for (const auto& row : rc.store.campaigns())
      if (state.empty() || domain::to_string(row.state) == state) out.push_back(campaign_json(rc.store, row, false));
    send_json(res, out);
  });
  get(R"(/api/campaigns/(\d+))", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    send_json(res, campaign_json(rc.store, campaign_or_404(rc.store, id_of(req)), true));
  });
  get(R"(/api/campaigns/(\d+)/events)", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    send_json(res, events_json(rc.store, campaign_or_404(rc.store, id_of(req)).id));
  });
  get(R"(/api/campaigns/(\d+)/nodes)", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    send_json(res, nodes_json(rc.store, campaign_or_404(rc.store, id_of(req))));
  });
  get(R"(/api/campaigns/(\d+)/loops)", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    send_json(res, loops_json(rc.store, campaign_or_404(rc.store, id_of(req)).id));
  });
  get(R"(/api/campaigns/(\d+)/runs)", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    send_json(res, runs_of(rc.store, campaign_or_404(rc.store, id_of(req)).id));
  });
  get(R"(/api/campaigns/(\d+)/transmissibility)", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    send_json(res, transmissibility_json(rc.store.transmissibility(campaign_or_404(rc.store, id_of(req)).id)));
  });
  get(R"(/api/campaigns/(\d+)/sweep)", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    const auto row = campaign_or_404(rc.store, id_of(req));
    res.set_header("Content-Disposition", "inline; filename=\"sweep-" + std::to_string(row.id) + ".json\"");
    send_json(res, sweep_json(rc.store, row));
  });
  get(R"(/api/campaigns/(\d+)/sweep\.csv)", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    const auto row = campaign_or_404(rc.store, id_of(req));
    res.set_header("Content-Disposition", "attachment; filename=\"sweep-" + std::to_string(row.id) + ".csv\"");
    res.set_content(sweep_csv(rc.store.transmissibility(row.id)), "text/csv");
  });
}

// A run's samples in at most `points` buckets of time, each bucket's min and max: a shaker's
// base and mass displacement (its envelope over the bucket), a load frame's displacement and force.
json samples_json(const httplib::Request& req, db::ReadSource& store, const db::RunInfo& r) {
  const auto [lo, hi] = store.time_span(r.id).value_or(std::make_pair(0.0, 0.0));
  const double t0 = query_number(req, "t0", lo, -1e12, 1e12), t1 = query_number(req, "t1", hi, -1e12, 1e12);
  if (t1 < t0) throw ApiError(400, "invalid parameter", "t1 must not be before t0");
  const int points = static_cast<int>(query_number(req, "points", 1000, 1, 100000));
  const bool shaker = shaker_run(store, r);
  json t_min, t_max, d_min, d_max, f_min, f_max, n;
  for (const db::Bucket& b : store.overview(r.id, t0, t1, points, shaker)) {
    t_min.push_back(b.t_min), t_max.push_back(b.t_max), d_min.push_back(b.disp_min), d_max.push_back(b.disp_max);
    f_min.push_back(b.force_min), f_max.push_back(b.force_max), n.push_back(b.n);
  }
  const std::string a = shaker ? "base_displacement" : "displacement", b = shaker ? "mass_displacement" : "force";
  const std::string bu = shaker ? "_mm" : "_N";
  return {{"run", r.id},
          {"t0", t0},
          {"t1", t1},
          {"buckets", n.size()},
          {"t_min", t_min},
          {"t_max", t_max},
          {a + "_min_mm", d_min},
          {a + "_max_mm", d_max},
          {b + "_min" + bu, f_min},
          {b + "_max" + bu, f_max},
          {"n", n}};
}

void add_run_reads(const Get& get) {
  get(R"(/api/runs/(\d+))", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    const db::RunInfo r = run_or_404(rc.store, id_of(req));
    const auto [t0, t1] = rc.store.time_span(r.id).value_or(std::make_pair(0.0, 0.0));
    send_json(res, {{"id", r.id},
                    {"campaign", r.campaign},
                    {"role", r.role},
                    {"state", r.state},
                    {"started_at", r.started_at},
                    {"ended_at", r.ended_at},
                    {"wall_anchor_unix", r.wall_anchor_unix},
                    {"samples", r.samples},
                    {"t_range_s", {t0, t1}},
                    {"quality", run_quality(rc.store, r.campaign, r.id)}});
  });
  get(R"(/api/runs/(\d+)/samples)", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    send_json(res, samples_json(req, rc.store, run_or_404(rc.store, id_of(req))));
  });
  get(R"(/api/runs/(\d+)/loop)", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    const auto points = static_cast<std::size_t>(query_number(req, "points", 2000, 2, 200000));
    send_json(res, loop_json(rc.store, rc.xy, id_of(req), points));
  });
}

void add_table_reads(const Get& get) {
  get("/api/tables", [](const httplib::Request&, httplib::Response& res, ReadContext& rc) {
    json out = json::array();
    for (const db::TableInfo& t : rc.store.tables()) out.push_back(table_json(t));
    send_json(res, out);
  });
  get(R"(/api/tables/(\d+))", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    const std::int64_t id = id_of(req);
    const auto t = rc.store.table(id);
    if (!t) throw ApiError(404, "not found", "no table " + std::to_string(id));
    json j = table_json(*t);
    j["document"] = json::parse(table_document(rc.store, id));
    send_json(res, j);
  });
  // A table scored on any run (a campaign's validation run, typically): the table from its initial
  // state over the run's displacements, against the measured forces, per branch.
  get(R"(/api/tables/(\d+)/score)", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    const std::int64_t id = id_of(req);
    if (!req.has_param("run")) throw ApiError(400, "invalid parameter", "run: the run to score the table on is required (?run=ID)", "run");
    const std::int64_t run = static_cast<std::int64_t>(query_number(req, "run", 0, 1, 9e15));
    const models::TableDocument doc = models::table_from_json(table_document(rc.store, id));
    const db::RunInfo r = run_or_404(rc.store, run);
    std::vector<double> x, f;
    rc.store.for_each_sample(r.id, 0, std::numeric_limits<std::int64_t>::max(), [&](const db::SampleRow& row) {
      x.push_back(row.disp);
      f.push_back(row.force);
    });
    if (x.size() < 2) throw ApiError(409, "conflict", "run " + std::to_string(run) + " has " + std::to_string(x.size()) + " sample(s): nothing to score on");
    json j = models::accuracy_json(models::score_table(doc.table, x, f));
    j["table"] = id;
    j["run"] = r.id;
    j["role"] = r.role;
    send_json(res, j);
  });
  get(R"(/api/tables/(\d+)/export)", [](const httplib::Request& req, httplib::Response& res, ReadContext& rc) {
    const std::int64_t id = id_of(req);
    const std::string format = req.has_param("format") ? req.get_param_value("format") : "json";
    if (!fmu::is_export_format(format)) throw ApiError(400, "invalid parameter", "format: '" + format + "' is not " + std::string(fmu::kExportFormats));
    const std::string text = table_document(rc.store, id);
    const std::string name = "hystlab_table_" + std::to_string(id);
    res.set_header("Content-Disposition", "attachment; filename=\"" + name + "." + format + "\"");
    if (format == "json") return res.set_content(text, "application/json");  // the stored document as it is
    fmu::ExportedFile f = fmu::export_element(text, format, name);
    res.set_content(std::move(f.bytes), f.media_type);
  });
}
}  // namespace

void add_read_routes(httplib::Server& s, const std::string& prefix, WithSource with) {
  const Get get = [&s, &prefix, with](const std::string& pattern, const ReadHandler& h) {
    s.Get(prefix + pattern, guarded([with, h](const httplib::Request& req, httplib::Response& res) { with(req, res, h); }));
  };
  add_campaign_reads(get);
  add_run_reads(get);
  add_table_reads(get);
}

}  // namespace hystlab::web
