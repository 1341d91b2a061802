#pragma once
// Reading a plan's fields (plan.cpp, sine_plan.cpp): each refusal names the field and the rule.
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "hystlab/daemon/plan.hpp"

namespace hystlab::daemon::fields {

[[noreturn]] inline void fail(const std::string& field, const std::string& why) { throw PlanError(field, "plan: " + field + " " + why); }

// j[f] within [lo, hi], or def when absent; where: the field's path prefix ("sweep.").
double number(const nlohmann::json& j, const char* f, double def, double lo, double hi, const std::string& where = "");

// j[f] an integer within [lo, hi], or def when absent.
int integer(const nlohmann::json& j, const char* f, int def, int lo, int hi, const std::string& where = "");

// A percentage: 0.5 or "0.5 %" or "0.5%", above 0 and at most max_pct.
double percent(const nlohmann::json& j, const char* f, double def, const std::string& where, double max_pct = 100);

// Refuses any field of object j not in the list, naming it and the known ones.
void only(const nlohmann::json& j, const std::string& where, std::initializer_list<const char*> known);

}  // namespace hystlab::daemon::fields
