#pragma once
// What the lab records with a campaign beside its plan: the specimen it ran on and the
// operator's notes. Set at submission (the plan's "specimen" and "notes") or later (a "record"
// event, newest wins: every change is kept in the campaign's events with its time). The API, the
// page, the CLI, the report and the HDF5 export read it here, so they never disagree.
#include <cstdint>
#include <optional>
#include <string>

#include "hystlab/db/store.hpp"
#include "hystlab/domain/record.hpp"

namespace hystlab::db {

struct CampaignRecord {
  std::string specimen, notes;
  std::string changed_at;  // the newest change after submission ("" when none)
};

// The record as it stands: the newest "record" event's, else the plan's fields.
[[nodiscard]] CampaignRecord campaign_record(ReadSource& store, const CampaignRow& row);

}  // namespace hystlab::db
