#pragma once
// A refused plan, and numbers as its messages write them (the parser's, the envelope check's).
#include <stdexcept>
#include <string>
#include <utility>

namespace hystlab::domain {

// A refused plan: what() is the whole sentence ("plan: ramp_rate_mm_s must be between 0.0001 and
// 20"), field the plan's field alone ("ramp_rate_mm_s", "limits.force_N"), so that a form can
// mark the input it came from.
struct PlanError : std::invalid_argument {
  explicit PlanError(const std::string& what) : std::invalid_argument(what) {}
  PlanError(std::string field_name, const std::string& what) : std::invalid_argument(what), field(std::move(field_name)) {}
  std::string field;
};

// A number as people write it: 0.0001, 20, 1e+06 (not std::to_string's 0.000100).
[[nodiscard]] std::string plan_number(double v);

}  // namespace hystlab::domain
