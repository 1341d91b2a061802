// A sine campaign's results: every step's point (measured, and predicted where the isolator has
// a model), and the sweep's report: one curve per amplitude and direction with its resonance
// (frequency, peak, half-power bandwidth, Q), and the jumps between up and down. As JSON, and
// the points as CSV (the page's downloads).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "hystlab/models/sweep_analysis.hpp"
#include "request_guard.hpp"
#include "routes.hpp"

namespace hystlab::web {
namespace {
json or_null(double v) { return std::isfinite(v) ? json(v) : json(); }

std::string csv_number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}

json point_json(const db::TransmissibilityInfo& t) {
  json j = t.detail.empty() ? json::object() : event_detail("transmissibility", t.detail);
  if (!j.is_object()) j = json::object();
  j["id"] = t.id;
  j["run"] = t.run;
  j["frequency_hz"] = t.frequency_hz;
  j["base_amplitude_mm"] = t.base_amplitude_mm;
  j["mass_amplitude_mm"] = t.mass_amplitude_mm;
  j["ratio"] = t.ratio;
  j["phase_rad"] = t.phase_rad;
  if (!j.contains("amplitude_mm")) j["amplitude_mm"] = t.demand_mm > 0 ? json(t.demand_mm) : json(t.base_amplitude_mm);
  if (!j.contains("direction")) j["direction"] = t.direction.empty() ? "up" : t.direction;
  j["predicted_ratio"] = or_null(t.predicted_ratio);
  j["predicted_phase_rad"] = or_null(t.predicted_phase_rad);
  // The step's hysteresis loop read as engineers do: its area against the elastic energy.
  j["equivalent_damping"] = or_null(models::equivalent_damping(t.ratio, t.phase_rad));
  j["predicted_equivalent_damping"] = or_null(models::equivalent_damping(t.predicted_ratio, t.predicted_phase_rad));
  return j;
}

// The plan's jump threshold (validated at submission): a number or "x %"; 10 % when absent.
double jump_threshold(const std::string& plan_text) {
  const json plan = json::parse(plan_text, nullptr, false);
  if (!plan.is_object() || !plan.contains("jump_threshold")) return 0.10;
  const json& v = plan["jump_threshold"];
  const double pct = v.is_number() ? v.get<double>() : v.is_string() ? std::strtod(v.get<std::string>().c_str(), nullptr) : 10.0;
  return pct > 0 ? pct / 100 : 0.10;
}

json resonance_json(const std::optional<models::Resonance>& r) {
  if (!r) return nullptr;
  return {{"frequency_hz", r->frequency_hz},
          {"peak_ratio", r->peak_ratio},
          {"lower_hz", r->lower_hz > 0 ? json(r->lower_hz) : json()},
          {"upper_hz", r->upper_hz > 0 ? json(r->upper_hz) : json()},
          {"bandwidth_hz", r->bandwidth_hz > 0 ? json(r->bandwidth_hz) : json()},
          {"q", r->q > 0 ? json(r->q) : json()},
          {"at_edge", r->at_edge},
          {"resolved", r->resolved}};
}

// points: point_json of each row, in the same order (each row's detail is parsed once).
json report_json(const std::vector<db::TransmissibilityInfo>& rows, const json& points, double threshold, bool predicted) {
  std::vector<models::SweepCurvePoint> pts;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const db::TransmissibilityInfo& t = rows[k];
    const double ratio = predicted ? t.predicted_ratio : t.ratio, phase = predicted ? t.predicted_phase_rad : t.phase_rad;
    if (!std::isfinite(ratio)) continue;
    pts.push_back({points[k]["amplitude_mm"].get<double>(), points[k]["direction"] == "up", {t.frequency_hz, ratio, phase}});
  }
  const models::SweepReport r = models::analyse_sweep(pts, threshold);
  json curves = json::array(), jumps = json::array();
  for (const models::SweepCurve& c : r.curves)
    curves.push_back({{"amplitude_mm", c.amplitude_mm},
                      {"direction", c.up ? "up" : "down"},
                      {"points", c.points.size()},
                      {"resonance", resonance_json(c.resonance)},
                      {"equivalent_damping", or_null(c.damping_at_resonance)}});
  for (const models::AmplitudeJumps& a : r.jumps)
    for (const models::Jump& j : a.jumps)
      jumps.push_back({{"amplitude_mm", a.amplitude_mm},
                       {"lo_hz", j.lo_hz},
                       {"hi_hz", j.hi_hz},
                       {"max_difference", j.max_difference},
                       {"up_jump_hz", j.up_jump_hz},
                       {"down_jump_hz", j.down_jump_hz}});
  // The backbone: each amplitude's resonance and the damping there, amplitude by amplitude (a
  // direction's own line), as an amplitude-dependent isolator is read.
  json backbone = json::array();
  for (const models::SweepCurve& c : r.curves)
    if (c.resonance && !c.resonance->at_edge)
      backbone.push_back({{"amplitude_mm", c.amplitude_mm},
                          {"direction", c.up ? "up" : "down"},
                          {"frequency_hz", c.resonance->frequency_hz},
                          {"peak_ratio", c.resonance->peak_ratio},
                          {"equivalent_damping", or_null(c.damping_at_resonance)}});
  std::stable_sort(backbone.begin(), backbone.end(), [](const json& a, const json& b) {
    return a["direction"] != b["direction"] ? a["direction"] == "up" : a["amplitude_mm"].get<double>() < b["amplitude_mm"].get<double>();
  });
  return {{"curves", curves}, {"jumps", jumps}, {"compared", r.jumps.size()}, {"backbone", backbone}};
}

constexpr const char* kCsvColumns[] = {"k",
                                       "pass",
                                       "amplitude_mm",
                                       "direction",
                                       "frequency_hz",
                                       "drive_mm",
                                       "base_amplitude_mm",
                                       "base_phase_rad",
                                       "mass_amplitude_mm",
                                       "mass_phase_rad",
                                       "ratio",
                                       "phase_rad",
                                       "thd",
                                       "control_error_pct",
                                       "band",
                                       "settle_cycles",
                                       "predicted_ratio",
                                       "predicted_phase_rad",
                                       "equivalent_damping",
                                       "predicted_equivalent_damping"};

std::string points_csv(const std::vector<db::TransmissibilityInfo>& rows) {
  std::string out;
  for (const char* c : kCsvColumns) out += (out.empty() ? "" : ",") + std::string(c);
  out += "\n";
  for (const db::TransmissibilityInfo& t : rows) {
    const json p = point_json(t);
    std::string line;
    for (const char* c : kCsvColumns) {
      if (c != kCsvColumns[0]) line += ",";
      const json& v = p.contains(c) ? p[c] : json();
      if (v.is_string())
        line += v.get<std::string>();
      else if (v.is_number())
        line += csv_number(v.get<double>());
    }
    out += line + "\n";
  }
  return out;
}
}  // namespace

json sweep_json(db::ReadSource& store, const db::CampaignRow& row) {
  const auto rows = store.transmissibility(row.id);
  const double threshold = jump_threshold(row.plan);
  json points = json::array();
  for (const db::TransmissibilityInfo& t : rows) points.push_back(point_json(t));
  const bool any_prediction = std::any_of(rows.begin(), rows.end(), [](const auto& t) { return std::isfinite(t.predicted_ratio); });
  return {{"campaign", row.id},
          {"jump_threshold", threshold},
          {"points", points},
          {"measured", report_json(rows, points, threshold, false)},
          {"predicted", any_prediction ? report_json(rows, points, threshold, true) : json()}};
}

json transmissibility_json(const std::vector<db::TransmissibilityInfo>& rows) {
  json out = json::array();
  for (const db::TransmissibilityInfo& t : rows) out.push_back(point_json(t));
  return out;
}
std::string sweep_csv(const std::vector<db::TransmissibilityInfo>& rows) { return points_csv(rows); }

}  // namespace hystlab::web
