// A run's x-y path (the force-displacement loop, or mass against base), decimated so that its
// shape is kept (models/xy_path.hpp), with the identified model's force on the same inputs; and
// the preview of a plan before it is submitted.
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>

#include "hystlab/domain/plan.hpp"
#include "hystlab/domain/plan_fields.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/simplified_sma.hpp"
#include "hystlab/models/xy_path.hpp"
#include "request_guard.hpp"
#include "routes.hpp"

namespace hystlab::web {
// A run's two columns, read once and then only what was added (a live run grows): a completed
// run of 10^7 samples is read from SQLite once, then every request decimates from memory.
struct RunXY {
  std::mutex mu;
  std::int64_t next_seq = 0;
  bool complete = false;
  std::vector<float> x, y;
  std::chrono::steady_clock::time_point used;
};

class XYCache {
 public:
  std::shared_ptr<RunXY> get(std::int64_t run) {
    std::lock_guard lk(mu_);
    auto& e = runs_[run];
    if (!e) e = std::make_shared<RunXY>();
    e->used = std::chrono::steady_clock::now();
    while (runs_.size() > kRuns) {  // the least recently used goes (its readers keep their copy alive)
      auto oldest = runs_.begin();
      for (auto it = runs_.begin(); it != runs_.end(); ++it)
        if (it->second->used < oldest->second->used) oldest = it;
      runs_.erase(oldest);
    }
    return e;
  }

 private:
  static constexpr std::size_t kRuns = 4;  // 10^7 samples are 80 MB as two float columns
  std::mutex mu_;
  std::map<std::int64_t, std::shared_ptr<RunXY>> runs_;
};

std::shared_ptr<XYCache> make_xy_cache() { return std::make_shared<XYCache>(); }

namespace {
double rounded(double v) { return std::round(v * 1e4) / 1e4; }  // 0.1 µm, 0.1 mN: the JSON stays short

std::unique_ptr<models::HysteresisModel> table_model(db::ReadSource& store, std::int64_t table_id) {
  const auto doc = store.table_document(table_id);
  if (!doc) return nullptr;
  return std::make_unique<models::PreisachModel>(std::make_shared<const models::EverettTable>(models::table_from_json(*doc).table));
}

}  // namespace

json loop_json(db::ReadSource& store, XYCache& cache, std::int64_t run_id, std::size_t points) {
  const auto run = store.run(run_id);
  if (!run) throw ApiError(404, "not found", "no run " + std::to_string(run_id));
  const auto campaign = store.campaign(run->campaign);
  const bool shaker = campaign && campaign->kind == domain::CampaignKind::sine;
  const auto xy = cache.get(run_id);
  std::lock_guard lk(xy->mu);
  if (!xy->complete) {
    xy->complete = !run->ended_at.empty();  // read before the rows: rows stored after this are read next time
    xy->next_seq = store.read_xy(run_id, xy->next_seq, shaker, xy->x, xy->y);
  }
  const models::PathReduction r = models::reduce_path(xy->x, xy->y, points);
  json xs = json::array(), ys = json::array();
  for (const std::size_t k : r.index) xs.push_back(rounded(xy->x[k])), ys.push_back(rounded(xy->y[k]));
  json out{{"run", run_id},
           {"kind", campaign ? domain::to_string(campaign->kind) : ""},
           {"x_label", shaker ? "base displacement (mm)" : "displacement (mm)"},
           {"y_label", shaker ? "mass displacement (mm)" : "force (N)"},
           {"samples", xy->x.size()},
           {"reversals", r.reversals},
           {"points", r.index.size()},
           {"x", xs},
           {"y", ys},
           {"model", nullptr}};
  const auto table = shaker ? std::nullopt : store.newest_table_of_campaign(run->campaign, "fot");
  if (table) {
    // Every reversal of x is kept, and a Preisach model's output depends on its input's
    // reversals only: the force at the kept points is the force on the whole run there.
    if (auto model = table_model(store, table->id)) {
      json f = json::array();
      for (const std::size_t k : r.index) f.push_back(rounded(model->step(xy->x[k])));
      out["model"] = {{"table", table->id}, {"force_N", f}, {"saturations", model->saturation_count()}};
    }
  }
  return out;
}

namespace {
json preview_json(ApiContext& c, const PlanRequest& req) {
  const std::string kind = req.plan.is_object() && req.plan.contains("kind") && req.plan["kind"].is_string() ? req.plan["kind"].get<std::string>() : "";
  const control::RigInfo rig = c.daemon.rig_info(c.daemon.rig_index(req.rig, kind));
  std::unique_ptr<models::HysteresisModel> model;
  std::string source;
  if (rig.kind != domain::RigKind::shaker) {
    if (const auto t = reader(c.db_path).newest_table_of_rig(rig.id, "fot"))
      model = table_model(reader(c.db_path), t->id), source = "table #" + std::to_string(t->id);
    if (!model) model = std::make_unique<models::SimplifiedSmaModel>(models::table1_parameters()), source = "the simplified model (the paper's Table 1)";
  }
  const control::PlanPreview v = c.daemon.preview(req.rig, req.plan, model.get());
  json out{{"rig", rig.name},
           {"kind", domain::to_string(v.kind)},
           {"duration_s", v.duration_s},
           {"nodes", v.nodes},
           {"peak_speed_mm_s", v.peak_speed_mm_s},
           {"samples", std::llround(v.samples)},
           {"sample_rate_hz", v.sample_rate_hz},
           {"time_scale", v.time_scale},
           // what the rig can give at its time scale: the wall time, and what is stored in rig time
           {"wall_s", v.duration_s / v.time_scale},
           {"stored_samples", std::llround(v.samples / v.time_scale)},
           {"stored_rate_hz", v.sample_rate_hz / v.time_scale},
           {"limits_applied", v.limits_applied}};
  if (v.design_budget_s > 0) {  // the plan parsed once more for its design's defaults (preview checked it)
    const domain::Plan p = domain::parse_plan(req.plan);
    out["design"] = {{"kind", "adaptive"},
                     {"budget_s", v.design_budget_s},
                     {"coarse_subdivisions", p.subdivisions},
                     {"finest_subdivisions", p.design.finest_subdivisions},
                     {"target_rms_N", p.design.target_rms_N},
                     {"min_gain", p.design.min_gain}};
  }
  if (model)
    out["peak_force_N"] = v.peak_force_N, out["force_source"] = source, out["force_limit_N"] = v.force_limit_N;
  else
    out["peak_accel_m_s2"] = v.peak_accel_m_s2;
  return out;
}
}  // namespace

void add_loop_routes(httplib::Server& s, ApiContext& c) {
  post_route(s, c, "/api/plans/preview",
             guarded([&c](const httplib::Request& req, httplib::Response& res) { send_json(res, preview_json(c, decode_plan_request(body_object(req)))); }));
  // The plan's fields as the parser checks them and the page's form offers them (one table).
  s.Get("/api/plans/form",
        guarded([form = domain::plan_form_json().dump()](const httplib::Request&, httplib::Response& res) { res.set_content(form, "application/json"); }));
}

}  // namespace hystlab::web
