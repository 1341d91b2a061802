#pragma once
// What the lab records with a campaign beside its plan: the specimen it ran on and the
// operator's notes. Set at submission (the plan's "specimen" and "notes") or later (a "record"
// event, newest wins: every change is kept in the campaign's events with its time). The API, the
// page, the CLI, the report and the HDF5 export read it here, so they never disagree.
#include <cstdint>
#include <optional>
#include <string>

#include "hystlab/db/store.hpp"

namespace hystlab::db {

inline constexpr std::size_t kSpecimenMaxChars = 200, kNotesMaxChars = 4000;

struct CampaignRecord {
  std::string specimen, notes;
  std::string changed_at;  // the newest change after submission ("" when none)
};

// The record as it stands: the newest "record" event's, else the plan's fields.
[[nodiscard]] CampaignRecord campaign_record(Store& store, const CampaignRow& row);

// A record event's detail: {"specimen": ..., "notes": ...} as JSON text.
[[nodiscard]] std::string record_detail(const CampaignRecord& r);

// Why `text` cannot be the field ("specimen" or "notes"), or nullopt when it can. Inline: the plan
// parser checks the plan's fields with it, and the plan fuzzer links no store.
[[nodiscard]] inline std::optional<std::string> record_field_problem(const std::string& field, const std::string& text) {
  const std::size_t most = field == "specimen" ? kSpecimenMaxChars : kNotesMaxChars;
  if (field != "specimen" && field != "notes") return "is not part of a campaign's record (specimen, notes)";
  if (text.size() > most) return "must be text of at most " + std::to_string(most) + " characters (got " + std::to_string(text.size()) + ")";
  if (field == "specimen" && text.find('\n') != std::string::npos) return "must be one line";
  return std::nullopt;
}

}  // namespace hystlab::db
