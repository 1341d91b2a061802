// The table of plan fields (hystlab/domain/plan_fields.hpp) is the parser's: every field it lists
// is read by parse_plan with the table's bounds, refused beyond them naming the field, and the
// form's inputs are unique. With the page built from GET /api/plans/form (browser test), a field
// added to the table is checked and offered without another list to keep in step.
#include <doctest/doctest.h>

#include <set>
#include <string>

#include "hystlab/domain/plan.hpp"
#include "hystlab/domain/plan_fields.hpp"

using hystlab::domain::FieldType;
using hystlab::domain::PlanError;
using hystlab::domain::PlanField;
using nlohmann::json;

namespace {

bool is_sine(const PlanField& f) {
  if (f.group == "sine") return true;
  for (const char* p :
       {"sweep.", "frequencies_hz", "amplitude", "settle", "measured_cycles", "control.", "jump_threshold", "direction", "resonance.", "dwell."})
    if (f.path.starts_with(p)) return true;
  return false;
}

// A valid plan of the field's kind, without the fields that exclude it.
json base_plan(const PlanField& f) {
  json p = is_sine(f) ? json{{"kind", "sine"},
                             {"sweep", {{"from_hz", 5}, {"to_hz", 60}}},
                             {"amplitudes_mm", {0.01}},
                             {"settle", {{"change", 2}}},
                             {"control", {{"tolerance", 5}, {"warning", 10}, {"abort", 30}}}}
                      : json{{"kind", "fot"}, {"range_mm", {0, 4}}, {"subdivisions", 4}};
  if (!is_sine(f) && f.path != "training_cycles") p["training"] = {{"max_cycles", 5}, {"until", json::object()}};
  if (f.path == "frequencies_hz") p.erase("sweep");
  if (f.path.starts_with("dwell.")) p.erase("sweep"), p["dwell"] = {{"frequency_hz", 17}, {"cycles", 100}};
  if (f.path == "amplitude_mm") p.erase("amplitudes_mm");
  if (f.path == "settle_cycles") p.erase("settle");
  if (f.path.starts_with("validation.")) p["validation"] = json::object();
  if (f.path.starts_with("design.")) p["design"] = {{"kind", "adaptive"}, {"budget_s", 1000}};
  return p;
}

// Sets the field's value at its path ("a.b", "a[1]"); a list field gets a list of one.
void set(json& plan, const PlanField& f, const json& value) {
  std::string path(f.path);
  json* o = &plan;
  for (std::size_t dot; (dot = path.find('.')) != std::string::npos; path = path.substr(dot + 1)) o = &(*o)[path.substr(0, dot)];
  if (const std::size_t br = path.find('['); br != std::string::npos) {
    const std::string name = path.substr(0, br);
    const std::size_t k = path[br + 1] == '0' ? 0 : 1;
    if (!o->contains(name)) (*o)[name] = name == "range_mm" ? json{0, 4} : json{-1, 5};
    (*o)[name][k] = value;
    return;
  }
  (*o)[path] = f.type == FieldType::list ? json::array({value}) : value;
}

std::string refused_field(const json& plan) {
  try {
    (void)hystlab::domain::parse_plan(plan);
  } catch (const PlanError& e) {
    return e.field + " | " + e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("every field of the table is read by the parser with the table's bounds") {
  int numeric = 0;
  for (const PlanField& f : hystlab::domain::plan_fields()) {
    if (f.type == FieldType::text || f.type == FieldType::choice) continue;
    CAPTURE(f.path);
    const std::string name = f.type == FieldType::list ? std::string(f.path) + "[0]" : std::string(f.path);
    const bool pair_low = f.path.ends_with("[0]"), pair_high = f.path.ends_with("[1]");
    // Beyond the top (a pair's low end: below its bottom, as low < high is checked first).
    json above = base_plan(f);
    set(above, f, f.type == FieldType::integer ? json(static_cast<long long>(f.max) + 1) : json(f.max * 2 + 1));
    if (!pair_low) CHECK(refused_field(above).starts_with(name + " |"));
    json below = base_plan(f);
    const json under = f.type == FieldType::percent   ? json(f.min)
                       : f.type == FieldType::integer ? json(static_cast<long long>(f.min) - 1)
                                                      : json(f.min - (f.min > 0 ? f.min / 2 : 1));
    set(below, f, under);
    if (!pair_high) CHECK(refused_field(below).starts_with(name + " |"));
    // Inside: never refused for its bounds (other rules may still name it: 1000 Hz needs 8 kHz).
    json inside = base_plan(f);
    set(inside, f, f.type == FieldType::integer ? json(static_cast<long long>(f.max)) : json(f.max));
    const std::string r = refused_field(inside);
    CHECK(r.find("must be between") == std::string::npos);
    CHECK(r.find("must be an integer from") == std::string::npos);
    CHECK(r.find("must be a percentage") == std::string::npos);
    ++numeric;
  }
  CHECK(numeric > 40);
}

TEST_CASE("the text and choice fields: their limits are the parser's") {
  for (const PlanField& f : hystlab::domain::plan_fields()) {
    CAPTURE(f.path);
    json p = base_plan(f);
    if (f.type == FieldType::text) {
      set(p, f, std::string(static_cast<std::size_t>(f.max), 'x'));
      CHECK(refused_field(p).empty());
      set(p, f, std::string(static_cast<std::size_t>(f.max) + 1, 'x'));
      CHECK(refused_field(p).starts_with(std::string(f.path) + " |"));
    } else if (f.type == FieldType::choice) {
      for (std::string_view rest = f.choices; !rest.empty();) {
        const std::size_t bar = rest.find('|');
        set(p, f, std::string(rest.substr(0, bar)));
        CHECK(refused_field(p).empty());
        rest = bar == std::string_view::npos ? std::string_view() : rest.substr(bar + 1);
      }
      set(p, f, "sideways");
      CHECK(refused_field(p).starts_with(std::string(f.path) + " |"));
    }
  }
}

TEST_CASE("the form's inputs: unique names, a group each, and the served table holds every field") {
  std::set<std::string_view> inputs, paths;
  for (const PlanField& f : hystlab::domain::plan_fields()) {
    CHECK(paths.insert(f.path).second);
    if (f.group.empty()) continue;
    CAPTURE(f.path);
    CHECK(inputs.insert(f.input).second);
    CHECK(std::set<std::string_view>{"fot", "sine", "common", "limits", "record"}.count(f.group) == 1);
    CHECK((f.optional || !f.value.empty()));  // a required input proposes a value
  }
  const json form = hystlab::domain::plan_form_json();
  REQUIRE(form["fields"].size() == hystlab::domain::plan_fields().size());
  CHECK(form["fields"][0]["input"] == "lo");
  CHECK(form["fields"][0]["label"] == "δmin");
  CHECK_THROWS_AS((void)hystlab::domain::plan_field("no_such_field"), std::logic_error);
}

TEST_CASE("the form's proposed values make a valid plan of each kind") {
  for (const char* kind : {"fot", "sine"}) {
    CAPTURE(kind);
    json plan{{"kind", kind}};
    const std::set<std::string_view> groups =
        std::string_view(kind) == "sine" ? std::set<std::string_view>{"sine", "common"} : std::set<std::string_view>{"fot", "common", "limits"};
    for (const PlanField& f : hystlab::domain::plan_fields()) {
      if (!groups.count(f.group) || f.value.empty() || f.path == "training_cycles" || f.path == "validation.reversals") continue;
      if (f.type == FieldType::list) {
        json values = json::array();
        for (std::string v(f.value); !v.empty();) {
          const std::size_t comma = v.find(',');
          values.push_back(std::stod(v.substr(0, comma)));
          v = comma == std::string::npos ? "" : v.substr(comma + 1);
        }
        plan[std::string(f.path)] = values;
      } else if (f.type == FieldType::choice) {
        set(plan, f, std::string(f.value));
      } else if (f.type == FieldType::integer) {
        set(plan, f, std::stoll(std::string(f.value)));
      } else {
        set(plan, f, std::stod(std::string(f.value)));
      }
    }
    CHECK(refused_field(plan).empty());
  }
}
