#include "hystlab/db/campaign_record.hpp"

#include <nlohmann/json.hpp>

namespace hystlab::db {
namespace {
using json = nlohmann::json;

std::string text_of(const json& j, const char* key) {
  return j.is_object() && j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : std::string();
}
}  // namespace

CampaignRecord campaign_record(Store& store, const CampaignRow& row) {
  CampaignRecord r;
  const json plan = json::parse(row.plan, nullptr, false);
  r.specimen = text_of(plan, "specimen");
  r.notes = text_of(plan, "notes");
  for (const EventRow& e : store.events(row.id)) {  // oldest first: the newest change wins
    if (e.kind != "record") continue;
    const json d = json::parse(e.detail, nullptr, false);
    if (!d.is_object()) continue;  // a record this version cannot read: the one before stands
    r.specimen = text_of(d, "specimen");
    r.notes = text_of(d, "notes");
    r.changed_at = e.at;
  }
  return r;
}

std::string record_detail(const CampaignRecord& r) { return json{{"specimen", r.specimen}, {"notes", r.notes}}.dump(); }

}  // namespace hystlab::db
