#pragma once
// What a plan will do, before it is submitted: how long it runs, how many nodes it measures, how
// fast the rig moves, and the force a model predicts on its input (the operator's check that
// the force limit is sane). Pure: the plan and a model in, numbers out.
#include <string>

#include "hystlab/control/values.hpp"
#include "hystlab/domain/plan.hpp"
#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::daemon {

using control::PlanPreview;

// model: the force model for the rig (the newest table, or the simplified model); null for a
// shaker plan. The model is reset and driven along the plan's input.
[[nodiscard]] PlanPreview preview_plan(const domain::Plan& plan, models::HysteresisModel* model);

}  // namespace hystlab::daemon
