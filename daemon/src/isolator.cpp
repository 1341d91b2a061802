#include "hystlab/daemon/isolator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fstream>
#include <sstream>

#include "hystlab/models/formats.hpp"
#include "hystlab/models/linear_spring.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/sdof.hpp"
#include "hystlab/models/simplified_sma.hpp"

namespace hystlab::daemon {
namespace {
constexpr double kG = 9.81;  // as the simulator's

[[noreturn]] void isolator_fail(const std::string& field, const std::string& why) { throw IsolatorError(field, field + " " + why); }

double isolator_positive(const nlohmann::json& j, const char* f, double def, const std::string& where) {
  if (!j.contains(f)) return def;
  if (!j[f].is_number() || !(j[f].get<double>() > 0) || !std::isfinite(j[f].get<double>())) isolator_fail(where + "." + f, "must be a number above 0");
  return j[f].get<double>();
}

IsolatorModel with_spring(IsolatorModel m, std::shared_ptr<const models::HysteresisModel> spring, double max_stiffness, const std::string& what) {
  m.spring = std::move(spring);
  m.max_stiffness_N_per_mm = max_stiffness;
  char buf[400];
  std::snprintf(buf, sizeof buf, "%g kg on %d springs (%s), %g N·s/m", m.mass_kg, m.springs, what.c_str(), m.damping_N_s_per_m);
  m.describe = buf;
  return m;
}
IsolatorModel with_spring(IsolatorModel m, const models::SmaParameters& p, const std::string& what) {
  return with_spring(std::move(m), std::make_shared<models::SimplifiedSmaModel>(p), std::max(p.KA, p.KM), what);
}

// The steepest slope of a spring's force over [lo, hi], loaded and unloaded (the integrator's
// time step is chosen from it): a Preisach table's is that of its steepest cell.
double steepest(const models::HysteresisModel& spring, double lo, double hi) {
  auto s = spring.clone();
  s->reset();
  double x0 = lo, f0 = s->step(lo), most = 0;
  for (int k = 1; k <= 800; ++k) {
    const double u = k <= 400 ? k / 400.0 : (800 - k) / 400.0;
    const double x = lo + (hi - lo) * u, f = s->step(x);
    if (x != x0) most = std::max(most, std::fabs(f - f0) / std::fabs(x - x0));
    x0 = x, f0 = f;
  }
  return most;
}

// A table identified on the load frame (a table document, docs/FORMATS.md): inline, a file, or
// a table of this daemon's store by id.
IsolatorModel with_table(IsolatorModel m, const nlohmann::json& j, const std::string& where, const TableLookup& stored) {
  std::string text, from = "inline";
  if (j.is_string() && stored) {  // a plan comes over the network: no file of the daemon's host is opened for it
    isolator_fail(where, "must be a stored table's id or a table document in a plan (a file path is for the rig's config)");
  } else if (j.is_number_integer()) {
    if (!stored) isolator_fail(where, "gives a stored table's id, which only a sine plan's isolator can (the store is not open when the config is read)");
    const auto id = j.get<std::int64_t>();
    const auto doc = stored(id);
    if (!doc) isolator_fail(where, "names table " + std::to_string(id) + ", which this daemon's store does not hold");
    text = *doc, from = "table " + std::to_string(id);
  } else if (j.is_string()) {
    std::ifstream in(j.get<std::string>());
    if (!in) isolator_fail(where, "names a file that cannot be read: " + j.get<std::string>());
    std::ostringstream all;
    all << in.rdbuf();
    text = all.str(), from = j.get<std::string>();
  } else if (j.is_object()) {
    text = j.dump();
  } else {
    isolator_fail(where, "must be a stored table's id, a table document (as GET /api/tables/ID/export?format=json gives it) or the path of one");
  }
  try {
    models::TableDocument doc = models::table_from_json(text);
    const models::Grid g = doc.table.grid();
    auto spring = std::make_shared<models::PreisachModel>(std::move(doc.table));
    const double k = steepest(*spring, g.lo, g.hi);
    // The provenance said with the prediction (the page's "predicted with ..."): which table,
    // how it was identified and from what.
    std::string what = "Preisach table n = " + std::to_string(g.n) + " (" + doc.provenance.method + ", " + from;
    if (!doc.provenance.source.empty()) what += ": " + doc.provenance.source;
    what += ")";
    return with_spring(std::move(m), spring, std::max(k, 1e-6), what);
  } catch (const std::exception& e) {
    isolator_fail(where, std::string("is not a table document: ") + e.what());
  }
}

// The compression at which the springs carry the weight (bisection, as the simulator finds it).
double preload_of(const IsolatorModel& iso) {
  double lo = 0, hi = 10;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    auto s = iso.spring->clone();
    s->reset();
    (iso.springs * s->step(mid) < iso.mass_kg * kG ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}
}  // namespace

IsolatorModel simulated_isolator() { return with_spring(IsolatorModel{}, models::table1_parameters(), "simplified model, Table 1"); }

IsolatorModel parse_isolator(const nlohmann::json& j, const std::string& where, const TableLookup& stored, const IsolatorModel* base) {
  if (!j.is_object()) isolator_fail(where, "must be an object: {\"mass_kg\": 13, \"springs\": 4, \"damping_N_s_per_m\": 58, \"params\": {...}}");
  for (const auto& [k, _] : j.items())
    if (k != "mass_kg" && k != "springs" && k != "damping_N_s_per_m" && k != "params" && k != "table" && k != "linear_N_per_mm")
      isolator_fail(where + "." + k, "is not a known field (mass_kg, springs, damping_N_s_per_m, params, table, linear_N_per_mm)");
  if (int(j.contains("params")) + int(j.contains("table")) + int(j.contains("linear_N_per_mm")) > 1)
    isolator_fail(where, "gives its springs one way: params, table or linear_N_per_mm");
  IsolatorModel m;
  if (base) m.mass_kg = base->mass_kg, m.springs = base->springs, m.damping_N_s_per_m = base->damping_N_s_per_m;
  m.mass_kg = isolator_positive(j, "mass_kg", m.mass_kg, where);
  if (j.contains("springs") && (!j["springs"].is_number_integer() || j["springs"] < 1 || j["springs"] > 1000))
    isolator_fail(where + ".springs", "must be an integer from 1 to 1000");
  m.springs = j.value("springs", m.springs);
  m.damping_N_s_per_m =
      j.contains("damping_N_s_per_m") && j["damping_N_s_per_m"] == 0 ? 0.0 : isolator_positive(j, "damping_N_s_per_m", m.damping_N_s_per_m, where);
  if (j.contains("table")) return with_table(m, j["table"], where + ".table", stored);
  if (j.contains("linear_N_per_mm")) {
    const double k = isolator_positive(j, "linear_N_per_mm", 0, where);
    char what[64];
    std::snprintf(what, sizeof what, "linear, %g N/mm", k);
    return with_spring(m, std::make_shared<models::LinearSpring>(k), k, what);
  }
  if (!j.contains("params")) return with_spring(m, models::table1_parameters(), "simplified model, Table 1");
  try {
    return with_spring(m, models::params_from_json(j["params"].dump()), "simplified model, the rig's parameters");
  } catch (const std::exception& e) {
    isolator_fail(where + ".params", std::string("are not simplified-model parameters: ") + e.what());
  }
}

std::vector<Predicted> predict_sweep(const IsolatorModel& iso, std::span<const PredictStep> steps) {
  std::vector<models::SdofSpring> springs;
  for (int k = 0; k < iso.springs; ++k) springs.push_back({iso.spring->clone(), iso.max_stiffness_N_per_mm});
  models::SdofOptions o;
  o.mass_kg = iso.mass_kg;
  o.damping_N_s_per_mm = iso.damping_N_s_per_m * 1e-3;
  o.preload_mm = preload_of(iso);
  models::SdofSystem sys(std::move(springs), o);
  std::vector<Predicted> out;
  out.reserve(steps.size());
  for (const PredictStep& s : steps) {
    // At least 3 s: a lightly damped isolator's free vibration from the step before decays over
    // 1/(ζω_n) (0.45 s for the simulated one) and would otherwise beat with the response.
    const int settle = std::max({30, s.settle_cycles, static_cast<int>(std::ceil(3.0 * s.frequency_hz))});
    const models::SteadyResponse r = models::steady_response(sys, s.base_amplitude_mm, s.frequency_hz, settle, s.measured_cycles);
    out.push_back({r.ratio, r.phase_rad});
  }
  return out;
}

}  // namespace hystlab::daemon
