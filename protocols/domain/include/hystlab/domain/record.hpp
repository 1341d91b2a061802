#pragma once
// A campaign's record beside its plan: the specimen it ran on and the operator's notes, and what
// each may hold. The plan parser and the record route check them here (db/campaign_record.hpp
// reads the record as it stands).
#include <cstddef>
#include <optional>
#include <string>

namespace hystlab::domain {

inline constexpr std::size_t kSpecimenMaxChars = 200, kNotesMaxChars = 4000;

// Why `text` cannot be the field ("specimen" or "notes"), or nullopt when it can.
[[nodiscard]] inline std::optional<std::string> record_field_problem(const std::string& field, const std::string& text) {
  const std::size_t most = field == "specimen" ? kSpecimenMaxChars : kNotesMaxChars;
  if (field != "specimen" && field != "notes") return "is not part of a campaign's record (specimen, notes)";
  if (text.size() > most) return "must be text of at most " + std::to_string(most) + " characters (got " + std::to_string(text.size()) + ")";
  if (field == "specimen" && text.find('\n') != std::string::npos) return "must be one line";
  return std::nullopt;
}

}  // namespace hystlab::domain
