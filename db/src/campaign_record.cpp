#include "hystlab/db/campaign_record.hpp"

#include <nlohmann/json.hpp>

namespace hystlab::db {
namespace {
using json = nlohmann::json;

std::string text_of(const json& j, const char* key) {
  return j.is_object() && j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : std::string();
}
}  // namespace

CampaignRecord campaign_record(ReadSource& store, const CampaignRow& row) {
  CampaignRecord r;
  const json plan = json::parse(row.plan, nullptr, false);
  r.specimen = text_of(plan, "specimen");
  r.notes = text_of(plan, "notes");
  for (const EventRow& e : store.events(row.id)) {  // oldest first: the newest change wins
    if (e.kind != "record") continue;
    std::string error;
    const auto d = domain::decode_event(e.kind, e.detail, error);
    if (!d) continue;  // a record this version cannot read: the one before stands
    const auto& rec = std::get<domain::RecordEvent>(*d);
    r.specimen = rec.specimen;
    r.notes = rec.notes;
    r.changed_at = e.at;
  }
  return r;
}

}  // namespace hystlab::db
