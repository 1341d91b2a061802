#include "hystlab/daemon/isolator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "hystlab/models/formats.hpp"
#include "hystlab/models/sdof.hpp"
#include "hystlab/models/simplified_sma.hpp"

namespace hystlab::daemon {
namespace {
constexpr double kG = 9.81;  // as the simulator's

[[noreturn]] void isolator_fail(const std::string& field, const std::string& why) { throw std::invalid_argument("config: " + field + " " + why); }

double isolator_positive(const nlohmann::json& j, const char* f, double def, const std::string& where) {
  if (!j.contains(f)) return def;
  if (!j[f].is_number() || !(j[f].get<double>() > 0) || !std::isfinite(j[f].get<double>())) isolator_fail(where + "." + f, "must be a number above 0");
  return j[f].get<double>();
}

IsolatorModel with_spring(IsolatorModel m, const models::SmaParameters& p, const std::string& what) {
  m.spring = std::make_shared<models::SimplifiedSmaModel>(p);
  m.max_stiffness_N_per_mm = std::max(p.KA, p.KM);
  char buf[160];
  std::snprintf(buf, sizeof buf, "%g kg on %d springs (%s), %g N·s/m", m.mass_kg, m.springs, what.c_str(), m.damping_N_s_per_m);
  m.describe = buf;
  return m;
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

IsolatorModel parse_isolator(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object()) isolator_fail(where, "must be an object: {\"mass_kg\": 13, \"springs\": 4, \"damping_N_s_per_m\": 58, \"params\": {...}}");
  for (const auto& [k, _] : j.items())
    if (k != "mass_kg" && k != "springs" && k != "damping_N_s_per_m" && k != "params")
      isolator_fail(where + "." + k, "is not a known field (mass_kg, springs, damping_N_s_per_m, params)");
  IsolatorModel m;
  m.mass_kg = isolator_positive(j, "mass_kg", m.mass_kg, where);
  if (j.contains("springs") && (!j["springs"].is_number_integer() || j["springs"] < 1 || j["springs"] > 1000))
    isolator_fail(where + ".springs", "must be an integer from 1 to 1000");
  m.springs = j.value("springs", m.springs);
  m.damping_N_s_per_m =
      j.contains("damping_N_s_per_m") && j["damping_N_s_per_m"] == 0 ? 0.0 : isolator_positive(j, "damping_N_s_per_m", m.damping_N_s_per_m, where);
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
