#pragma once
// The lab view's answers as JSON (docs/API.md, "The lab view"): pure, from LabReads' rows and
// the broker's snapshot (lab::LabWatch).
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hystlab/db/lab_reads.hpp"

namespace hystlab::web {

[[nodiscard]] nlohmann::json mqtt_status(const nlohmann::json& live);
// Daemons and rigs from the database, each with what the broker said last (null: nothing yet);
// a daemon or rig the broker knows but the database not yet (a new daemon) is listed too.
[[nodiscard]] nlohmann::json lab_overview_json(const std::string& lab, const std::vector<db::LabDaemon>& daemons, const std::vector<db::LabRig>& rigs,
                                               const nlohmann::json& live);
[[nodiscard]] nlohmann::json campaigns_json(const std::vector<db::LabCampaign>& campaigns);
[[nodiscard]] nlohmann::json campaign_json(const db::LabCampaign& c, const std::vector<db::LabRun>& runs, const std::vector<db::LabEvent>& events,
                                           const std::vector<db::LabTable>& tables);
[[nodiscard]] nlohmann::json tables_json(const std::vector<db::LabTable>& tables);
[[nodiscard]] nlohmann::json overview_json(const db::LabOverview& o);

}  // namespace hystlab::web
