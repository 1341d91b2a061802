#pragma once
// The API's route groups, each in its own file, and the JSON of the rows they share.
#include <httplib.h>

#include <memory>
#include <string>
#include <vector>

#include "api_support.hpp"
#include "hystlab/domain/events.hpp"

namespace hystlab::web {

void add_status_routes(httplib::Server& s, ApiContext& c);         // status, rigs
void add_campaign_routes(httplib::Server& s, ApiContext& c);       // campaigns, commands, events, nodes, runs
void add_data_routes(httplib::Server& s, ApiContext& c);           // samples, tables, exports, evaluation
void add_loop_routes(httplib::Server& s, ApiContext& c);           // runs' x-y paths, plan previews
void add_h5_routes(httplib::Server& s, ApiContext& c);             // a run or a campaign as an HDF5 file
void add_page_route(httplib::Server& s, const std::string& root);  // the page's files: after every other route

db::CampaignRow campaign_or_404(db::ReadSource& store, std::int64_t id);
db::RunInfo run_or_404(db::ReadSource& store, std::int64_t id);
std::string table_document(db::ReadSource& store, std::int64_t id);             // 404 when none
bool shaker_run(db::ReadSource& store, const db::RunInfo& r);                   // its campaign is a sine sweep
json runs_of(db::ReadSource& store, std::int64_t campaign);                     // .../runs
json transmissibility_json(const std::vector<db::TransmissibilityInfo>& rows);  // .../transmissibility
std::string sweep_csv(const std::vector<db::TransmissibilityInfo>& rows);       // .../sweep.csv

json campaign_json(db::ReadSource& store, const db::CampaignRow& row, bool details);
json node_json(const db::NodeInfo& n);
json table_json(const db::TableInfo& t);
json parse_or_text(const std::string& s);  // stored JSON text as JSON (or as the text itself)
// A stored event's detail as the API shows it: read through its type (domain/events.hpp), so that
// the page gets the schema's fields; a kind this version does not know (a "state" event's
// reason) or a detail that does not fit its type, as stored (kept, never dropped).
json event_detail(const std::string& kind, const std::string& detail);

// What the report (report_route.cpp) shares with the routes that serve the same JSON.
json rig_json(const control::DaemonInterface& d, std::size_t k);     // GET /api/rigs/NAME
json nodes_json(db::ReadSource& store, const db::CampaignRow& row);  // .../nodes
json events_json(db::ReadSource& store, std::int64_t campaign);      // .../events
json loops_json(db::ReadSource& store, std::int64_t campaign);       // .../loops
json sweep_json(db::ReadSource& store, const db::CampaignRow& row);  // .../sweep
class XYCache;                                                       // runs' x-y columns, read once
std::shared_ptr<XYCache> make_xy_cache();
json loop_json(db::ReadSource& store, XYCache& cache, std::int64_t run_id, std::size_t points);  // /api/runs/ID/loop
void add_report_routes(httplib::Server& s, ApiContext& c);                                       // GET /api/campaigns/ID/report.html

// A run's data quality, from its "quality" event (null while it runs), with warnings in words.
json run_quality(db::ReadSource& store, std::int64_t campaign, std::int64_t run);
// The warnings of a result computed over a run (a table, a transmissibility point).
json result_warnings(const json& quality);

}  // namespace hystlab::web
