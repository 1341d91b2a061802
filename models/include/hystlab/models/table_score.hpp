#pragma once
// A table scored on a record it was not built from (or any record): the table run from its
// initial state (δmin of its grid, memory wiped) over the record's displacements, its forces
// compared with the measured ones per branch (models::compare), as JSON for the store and the API.
#include <nlohmann/json.hpp>
#include <span>

#include "hystlab/models/accuracy.hpp"
#include "hystlab/models/everett_table.hpp"

namespace hystlab::models {

[[nodiscard]] AccuracyReport score_table(const EverettTable& table, std::span<const double> displacement, std::span<const double> force);

// {"overall": {"samples", "rms_N", "max_N", "rms_norm", "max_norm"}, "ascending": {...},
//  "descending": {...}, "reference_range_N", "loop_energy_rel_error" (when the record closes)}
[[nodiscard]] nlohmann::json accuracy_json(const AccuracyReport& report);

}  // namespace hystlab::models
