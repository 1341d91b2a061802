#pragma once
// Reading a plan's fields (plan.cpp, sine_plan.cpp): each refusal names the field and the rule.
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "hystlab/domain/plan_error.hpp"
#include "hystlab/domain/plan_fields.hpp"

namespace hystlab::domain::fields {

[[noreturn]] inline void fail(const std::string& field, const std::string& why) { throw PlanError(field, "plan: " + field + " " + why); }

// The bounds of every field come from the table (hystlab/domain/plan_fields.hpp), at the path
// where + f ("sweep." + "from_hz"); def when the field is absent.
double number(const nlohmann::json& j, const char* f, double def, const std::string& where = "");
int integer(const nlohmann::json& j, const char* f, int def, const std::string& where = "");
// A percentage: 0.5 or "0.5 %" or "0.5%", above 0 and at most the table's max.
double percent(const nlohmann::json& j, const char* f, double def, const std::string& where = "");
// One element of a list field (path: the table's, name: the element's, "amplitudes_mm[2]").
double element(const nlohmann::json& v, const std::string& path, const std::string& name);

// Refuses any field of object j not in the list, naming it and the known ones.
void only(const nlohmann::json& j, const std::string& where, std::initializer_list<const char*> known);

}  // namespace hystlab::domain::fields
