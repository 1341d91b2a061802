// GET /api/campaigns/ID/report.html: the campaign report (report_html.hpp), assembled from the
// store as the API serves each part, so that the report and the page cannot disagree.
#include <chrono>
#include <ctime>

#include "report_html.hpp"
#include "request_guard.hpp"
#include "routes.hpp"

namespace hystlab::web {
namespace {

std::string utc_now() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char b[32];
  std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return b;
}

// The campaign's own run (the newest, after a resume), not the validation run beside it.
std::int64_t own_run(const json& campaign) {
  std::int64_t run = 0;
  for (const json& r : campaign["runs"])
    if (r.value("role", "") != "validation") run = r.value("id", std::int64_t{0});
  return run;
}

json report_document(ApiContext& c, db::ReadSource& store, const db::CampaignRow& row, XYCache& cache) {
  json doc{{"campaign", campaign_json(store, row, true)},
           {"software", std::string("hystlab ") + HYSTLAB_VERSION},
           {"generated_at", utc_now()},
           {"events", events_json(store, row.id)},
           {"loops", loops_json(store, row.id)},
           {"rig", nullptr}};
  const std::string rig = doc["campaign"].value("rig", "");
  for (std::size_t k = 0; k < c.daemon.rig_count(); ++k)
    if (c.daemon.rig_info(k).name == rig) doc["rig"] = rig_json(c.daemon, k);
  if (row.kind == domain::CampaignKind::sine) {
    doc["sweep"] = sweep_json(store, row);
    return doc;
  }
  if (row.kind == domain::CampaignKind::fot) doc["nodes"] = nodes_json(store, row);
  json provenance = json::object();  // each table's own account of how it was made (method, prior, folds, ...)
  for (const json& t : doc["campaign"]["tables"])
    if (const auto text = store.table_document(t.value("id", std::int64_t{0}))) {
      const json table = json::parse(*text, nullptr, false);
      if (table.is_object() && table.contains("provenance")) provenance[std::to_string(t.value("id", 0))] = table["provenance"];
    }
  doc["provenance"] = provenance;
  if (const std::int64_t run = own_run(doc["campaign"])) {
    try {
      doc["loop"] = loop_json(store, cache, run, 2000);
    } catch (const ApiError&) {  // a run without samples (a campaign that never started): no loop
    }
  }
  return doc;
}

}  // namespace

void add_report_routes(httplib::Server& s, ApiContext& c) {
  auto cache = make_xy_cache();
  s.Get(R"(/api/campaigns/(\d+)/report\.html)", guarded([&c, cache](const httplib::Request& req, httplib::Response& res) {
          auto& store = reader(c.db_path);
          const auto row = campaign_or_404(store, path_id(req));
          res.set_header("Content-Disposition", "inline; filename=\"hystlab-campaign-" + std::to_string(row.id) + "-report.html\"");
          res.set_content(report::render_html(report_document(c, store, row, *cache)), "text/html; charset=utf-8");
        }));
}

}  // namespace hystlab::web
