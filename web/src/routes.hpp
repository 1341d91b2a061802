#pragma once
// The API's route groups, each in its own file.
#include <httplib.h>

#include <string>

#include "api_support.hpp"

namespace hystlab::web {

void add_status_routes(httplib::Server& s, ApiContext& c);    // status, rigs
void add_campaign_routes(httplib::Server& s, ApiContext& c);  // campaigns, commands, events, nodes, runs
void add_data_routes(httplib::Server& s, ApiContext& c);      // samples, tables, exports, evaluation

// Row helpers shared by routes and the event stream: each reads the columns its SELECT names.
inline const std::string kNodeSelect =
    "SELECT f.id, r.campaign_id, f.run_id, alpha, beta, force_alpha, force_alpha_beta, f.t FROM fot_nodes f JOIN runs r ON r.id = f.run_id ";
inline const std::string kTableSelect = "SELECT id, campaign_id, run_id, method, n, range_lo, range_hi, created_at, accuracy FROM tables ";
json campaign_json(db::Store& store, const db::CampaignRow& row, bool details);
json node_json(db::Statement& st);       // a row of kNodeSelect
json table_row_json(db::Statement& st);  // a row of kTableSelect

}  // namespace hystlab::web
