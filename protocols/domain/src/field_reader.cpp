#include "field_reader.hpp"

#include <cstdio>
#include <cstdlib>

namespace hystlab::domain {

std::string plan_number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

namespace fields {
using nlohmann::json;

double number(const json& j, const char* f, double def, const std::string& where) {
  const PlanField& b = plan_field(where + f);
  if (!j.contains(f)) return def;
  if (!j[f].is_number() || !std::isfinite(j[f].get<double>())) fail(where + f, "must be a number");
  const double v = j[f].get<double>();
  if (v < b.min || v > b.max) fail(where + f, "must be between " + plan_number(b.min) + " and " + plan_number(b.max));
  return v;
}

int integer(const json& j, const char* f, int def, const std::string& where) {
  const PlanField& b = plan_field(where + f);
  if (!j.contains(f)) return def;
  if (!j[f].is_number_integer() || j[f].get<double>() < b.min || j[f].get<double>() > b.max)
    fail(where + f, "must be an integer from " + plan_number(b.min) + " to " + plan_number(b.max));
  return j[f].get<int>();
}

double percent(const json& j, const char* f, double def, const std::string& where) {
  const PlanField& b = plan_field(where + f);
  if (!j.contains(f)) return def;
  double v = NAN;
  if (j[f].is_number()) {
    v = j[f].get<double>();
  } else if (j[f].is_string()) {
    std::string t = j[f].get<std::string>();
    while (!t.empty() && (t.back() == ' ' || t.back() == '%')) t.pop_back();
    char* end = nullptr;
    v = std::strtod(t.c_str(), &end);
    if (t.empty() || end != t.c_str() + t.size()) v = NAN;
  }
  if (!std::isfinite(v) || !(v > b.min) || v > b.max)
    fail(where + f, "must be a percentage above " + plan_number(b.min) + " and at most " + plan_number(b.max) + ", e.g. 0.5 or \"0.5 %\"");
  return v;
}

double element(const json& v, const std::string& path, const std::string& name) {
  const PlanField& b = plan_field(path);
  if (!v.is_number() || !std::isfinite(v.get<double>())) fail(name, "must be a number");
  const double x = v.get<double>();
  if (x < b.min || x > b.max)
    fail(name, "must be from " + plan_number(b.min) + " to " + plan_number(b.max) + (b.unit.empty() ? "" : " " + std::string(b.unit)));
  return x;
}

void only(const json& j, const std::string& where, std::initializer_list<const char*> known) {
  std::string list;
  for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
  for (const auto& [k, _] : j.items()) {
    bool ok = false;
    for (const char* n : known) ok = ok || k == n;
    if (!ok) fail(where + k, "is not a known field (" + list + ")");
  }
}

}  // namespace fields
}  // namespace hystlab::domain
