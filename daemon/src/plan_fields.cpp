#include "plan_fields.hpp"

#include <cstdlib>

namespace hystlab::daemon::fields {
using nlohmann::json;

double number(const json& j, const char* f, double def, double lo, double hi, const std::string& where) {
  if (!j.contains(f)) return def;
  if (!j[f].is_number() || !std::isfinite(j[f].get<double>())) fail(where + f, "must be a number");
  const double v = j[f].get<double>();
  if (v < lo || v > hi) fail(where + f, "must be between " + plan_number(lo) + " and " + plan_number(hi));
  return v;
}

int integer(const json& j, const char* f, int def, int lo, int hi, const std::string& where) {
  if (!j.contains(f)) return def;
  if (!j[f].is_number_integer() || j[f].get<long long>() < lo || j[f].get<long long>() > hi)
    fail(where + f, "must be an integer from " + std::to_string(lo) + " to " + std::to_string(hi));
  return j[f].get<int>();
}

double percent(const json& j, const char* f, double def, const std::string& where, double max_pct) {
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
  if (!std::isfinite(v) || !(v > 0) || v > max_pct)
    fail(where + f, "must be a percentage above 0 and at most " + plan_number(max_pct) + ", e.g. 0.5 or \"0.5 %\"");
  return v;
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

}  // namespace hystlab::daemon::fields
