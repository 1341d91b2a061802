#pragma once
// Loop figures as JSON (the CLI's --json, the daemon's store, the API): one object per cycle, in
// the units of its names.
#include <nlohmann/json.hpp>
#include <vector>

#include "hystlab/models/loop_figures.hpp"

namespace hystlab::models {

[[nodiscard]] nlohmann::json loop_json(const LoopFigures& loop);
[[nodiscard]] nlohmann::json loops_json(const std::vector<LoopFigures>& loops);

}  // namespace hystlab::models
