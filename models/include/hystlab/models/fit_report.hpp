#pragma once
// A least-squares fit's figures as the JSON the table's provenance carries: one shape for the CLI's
// `fit` and the daemon's end-of-campaign table.
#include <nlohmann/json.hpp>

#include "hystlab/models/preisach_fit.hpp"

namespace hystlab::models {

[[nodiscard]] nlohmann::json fit_provenance(const PreisachFitResult& r);

}  // namespace hystlab::models
