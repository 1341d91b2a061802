#include "hystlab/models/loop_report.hpp"

namespace hystlab::models {
namespace {
using nlohmann::json;
json point(const TransitionPoint& p) { return json{{"displacement_mm", p.displacement}, {"force_N", p.force}}; }
json knees(const BranchKnees& b) {
  return json{{"lower_mm", b.lower_mm},
              {"lower_N", b.lower_N},
              {"upper_mm", b.upper_mm},
              {"upper_N", b.upper_N},
              {"slopes_N_mm", {b.slope_start, b.slope_middle, b.slope_end}},
              {"rms_N", b.rms_N},
              {"line_rms_N", b.line_rms_N},
              {"plateau", b.has_plateau()}};
}
}  // namespace

json loop_json(const LoopFigures& L) {
  json j{{"samples", {L.begin, L.turn, L.end}},
         {"starts_at", L.starts_at_max ? "max" : "min"},
         {"min_mm", L.min_mm},
         {"max_mm", L.max_mm},
         {"force_at_min_N", L.force_at_min_N},
         {"force_at_max_N", L.force_at_max_N},
         {"peak_force_N", L.peak_force_N},
         {"return_N", L.return_N},
         {"residual_mm", std::isfinite(L.residual_mm) ? json(L.residual_mm) : json(nullptr)},
         {"energy_Nmm", L.energy_Nmm},
         {"secant_stiffness_N_mm", L.secant_stiffness_N_mm},
         {"strain_energy_Nmm", L.strain_energy_Nmm},
         {"damping_ratio", L.damping_ratio}};
  json pl = json::array();
  for (const PlateauForce& p : L.plateaus) pl.push_back({{"at_mm", p.at_mm}, {"loading_N", p.loading_N}, {"unloading_N", p.unloading_N}});
  j["plateaus"] = std::move(pl);
  if (L.loading) j["loading_knees"] = knees(*L.loading);
  if (L.unloading) j["unloading_knees"] = knees(*L.unloading);
  if (L.transformation)
    j["transformation"] = {
        {"Ms", point(L.transformation->Ms)}, {"Mf", point(L.transformation->Mf)}, {"As", point(L.transformation->As)}, {"Af", point(L.transformation->Af)}};
  return j;
}

json loops_json(const std::vector<LoopFigures>& loops) {
  json a = json::array();
  for (const LoopFigures& L : loops) a.push_back(loop_json(L));
  return a;
}

}  // namespace hystlab::models
