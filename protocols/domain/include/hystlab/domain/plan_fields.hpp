#pragma once
// Every field of a plan that takes a value, in one table: where it is in the plan, its words and
// unit, what the parser accepts, and (for those the page's form offers) its input. The parser
// reads each field's bounds from here (plan.cpp, sine_plan.cpp), GET /api/plans/form serves it,
// and the page builds its new-campaign form from that answer: a field added here is checked by
// the parser with these bounds and offered by the form (tests/protocols/test_plan_fields.cpp,
// tests/browser/page_test.mjs).
#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string_view>

namespace hystlab::domain {

enum class FieldType : std::uint8_t {
  number,   // a finite number within [min, max]
  integer,  // a whole number within [min, max]
  percent,  // above min (0) and at most max: 0.5 or "0.5 %"
  list,     // numbers within [min, max], one input holding several
  text,     // free text (min, max unused)
  choice,   // one of the choices
};
[[nodiscard]] const char* to_string(FieldType t) noexcept;

struct PlanField {
  std::string_view path;   // in the plan: "dwell_s", "sweep.from_hz"; one end of a pair: "range_mm[0]"
  std::string_view words;  // as the form and the messages say it: "dwell"
  std::string_view unit;   // "s", "mm/s", "%" or empty
  double min = 0, max = 0;
  FieldType type = FieldType::number;
  // The form's input (group empty: no input, the parser's alone).
  std::string_view group;        // "fot", "sine", "common", "limits", "record"
  std::string_view input;        // the input's name
  std::string_view label;        // the input's label when it is not the words ("or these frequencies")
  std::string_view value;        // what the form proposes
  std::string_view placeholder;  // what a blank optional input means
  bool optional = false;
  std::string_view choices;  // choice: its values, separated by '|'
};

// In the form's order (its inputs), then the parser's other fields.
[[nodiscard]] std::span<const PlanField> plan_fields() noexcept;
// The field at path (a pair's end: "range_mm[0]"); throws std::logic_error for a path the table
// does not hold (a parser reading a field not listed is a programming error, found by any test
// that parses a plan of that kind).
[[nodiscard]] const PlanField& plan_field(std::string_view path);
// The table as GET /api/plans/form serves it: {"fields": [{"path", "words", "unit", "min", "max",
// "type", "group", "input", "label", "value", "placeholder", "optional", "choices"}, ...]}.
[[nodiscard]] nlohmann::json plan_form_json();

}  // namespace hystlab::domain
