#include "hystlab/domain/plan.hpp"

#include "field_reader.hpp"
#include "hystlab/domain/record.hpp"
#include "hystlab/models/fot_design.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace hystlab::domain {

namespace {
using nlohmann::json;

using fields::fail;
using fields::number;

// [low, high]; bounded: each end within the table's bounds for f[0] and f[1].
std::pair<double, double> pair_of(const json& j, const std::string& f, bool bounded = true) {
  if (!j.is_array() || j.size() != 2 || !j[0].is_number() || !j[1].is_number()) fail(f, "must be [low, high]");
  const double a = j[0].get<double>(), b = j[1].get<double>();
  if (!std::isfinite(a) || !std::isfinite(b) || !(b > a)) fail(f, "must be [low, high] with low < high");
  if (bounded) {
    (void)fields::element(j[std::size_t{0}], f + "[0]", f + "[0]");
    (void)fields::element(j[std::size_t{1}], f + "[1]", f + "[1]");
  }
  return {a, b};
}

Limits parse_limits(const json& j, double lo, double hi) {
  Limits l;
  l.displacement_min_mm = lo - 0.5;
  l.displacement_max_mm = hi + 0.5;
  if (j.is_null()) return l;
  if (!j.is_object()) fail("limits", "must be an object");
  for (const auto& [k, _] : j.items())
    if (k != "displacement_mm" && k != "force_N" && k != "rate_mm_s" && k != "safe_position_mm" && k != "safe_rate_mm_s")
      fail("limits." + k, "is not a known field");
  if (j.contains("displacement_mm")) std::tie(l.displacement_min_mm, l.displacement_max_mm) = pair_of(j["displacement_mm"], "limits.displacement_mm");
  l.force_max_N = number(j, "force_N", l.force_max_N, "limits.");
  l.rate_max_mm_s = number(j, "rate_mm_s", l.rate_max_mm_s, "limits.");
  l.safe_position_mm = number(j, "safe_position_mm", lo, "limits.");
  l.safe_rate_mm_s = number(j, "safe_rate_mm_s", l.safe_rate_mm_s, "limits.");
  if (l.safe_position_mm < l.displacement_min_mm || l.safe_position_mm > l.displacement_max_mm)
    fail("limits.safe_position_mm", "must lie inside limits.displacement_mm");
  return l;
}
Training parse_training(const json& j) {
  Training t;
  if (!j.contains("training")) {
    t.max_cycles = fields::integer(j, "training_cycles", 0);
    return t;
  }
  if (j.contains("training_cycles")) fail("training_cycles", "and training: give one of them");
  const json& tr = j["training"];
  if (!tr.is_object()) fail("training", "must be an object: {\"max_cycles\": 40, \"until\": {...}}");
  for (const auto& [k, _] : tr.items())
    if (k != "max_cycles" && k != "until") fail("training." + k, "is not a known field (max_cycles, until)");
  if (!tr.contains("max_cycles")) fail("training.max_cycles", "is required");
  t.max_cycles = fields::integer(tr, "max_cycles", 0, "training.");
  if (!tr.contains("until")) return t;
  const json& u = tr["until"];
  if (!u.is_object()) fail("training.until", "must be an object: {\"peak_force_change\": \"0.5 %\", \"energy_change\": \"2 %\", \"consecutive\": 3}");
  for (const auto& [k, _] : u.items())
    if (k != "peak_force_change" && k != "energy_change" && k != "consecutive")
      fail("training.until." + k, "is not a known field (peak_force_change, energy_change, consecutive)");
  t.until = true;
  t.peak_force_change_pct = fields::percent(u, "peak_force_change", t.peak_force_change_pct, "training.until.");
  t.energy_change_pct = fields::percent(u, "energy_change", t.energy_change_pct, "training.until.");
  t.consecutive = fields::integer(u, "consecutive", t.consecutive, "training.until.");
  if (t.consecutive >= t.max_cycles) fail("training.until.consecutive", "must be below training.max_cycles");
  return t;
}

Validation parse_validation(const json& j, const Plan& p) {
  Validation v{true, 12, p.lo_mm, p.hi_mm, p.ramp_rate_mm_s, 1};
  if (!j.contains("validation")) return v;
  const json& b = j["validation"];
  if (b.is_boolean()) {
    v.enabled = b.get<bool>();
    return v;
  }
  if (!b.is_object()) fail("validation", "must be an object ({\"reversals\": 12, ...}) or false");
  for (const auto& [k, _] : b.items())
    if (k != "reversals" && k != "range_mm" && k != "rate_mm_s" && k != "seed")
      fail("validation." + k, "is not a known field (reversals, range_mm, rate_mm_s, seed)");
  v.reversals = fields::integer(b, "reversals", v.reversals, "validation.");
  if (b.contains("range_mm")) std::tie(v.lo_mm, v.hi_mm) = pair_of(b["range_mm"], "validation.range_mm", false);
  if (v.lo_mm < p.lo_mm || v.hi_mm > p.hi_mm) fail("validation.range_mm", "must lie inside range_mm (the tables cover only it)");
  v.rate_mm_s = number(b, "rate_mm_s", v.rate_mm_s, "validation.");
  if (b.contains("seed")) {
    if (!b["seed"].is_number_integer() || b["seed"].get<double>() < 0) fail("validation.seed", "must be a non-negative integer");
    v.seed = b["seed"].get<std::uint64_t>();
  }
  return v;
}

std::vector<double> parse_plateaus(const json& j, const Plan& p) {
  std::vector<double> out;
  if (!j.contains("plateaus_mm")) return out;
  if (!j["plateaus_mm"].is_array() || j["plateaus_mm"].size() > 20) fail("plateaus_mm", "must be an array of at most 20 displacements");
  for (std::size_t k = 0; k < j["plateaus_mm"].size(); ++k) {
    const json& v = j["plateaus_mm"][k];
    const std::string f = "plateaus_mm[" + std::to_string(k) + "]";
    (void)fields::element(v, "plateaus_mm", f);
    if (v.get<double>() <= p.lo_mm || v.get<double>() >= p.hi_mm) fail(f, "must lie inside range_mm");
    out.push_back(v.get<double>());
  }
  return out;
}

// A grid of its own: 3 to 201 strictly increasing nodes; range_mm and subdivisions, when given, must agree.
void parse_nodes(const json& j, Plan& p) {
  const json& a = j["nodes_mm"];
  if (!a.is_array() || a.size() < 2 || a.size() > 201) fail("nodes_mm", "must be an array of 2 to 201 node positions (mm)");
  for (std::size_t k = 0; k < a.size(); ++k) {
    const std::string f = "nodes_mm[" + std::to_string(k) + "]";
    if (!a[k].is_number() || !std::isfinite(a[k].get<double>())) fail(f, "must be a number");
    if (k > 0 && !(a[k].get<double>() > a[k - 1].get<double>())) fail(f, "must be above nodes_mm[" + std::to_string(k - 1) + "] (nodes increase)");
    p.nodes_mm.push_back(a[k].get<double>());
  }
  p.lo_mm = p.nodes_mm.front();
  p.hi_mm = p.nodes_mm.back();
  p.subdivisions = static_cast<int>(p.nodes_mm.size()) - 1;
  if (j.contains("range_mm") && pair_of(j["range_mm"], "range_mm") != std::make_pair(p.lo_mm, p.hi_mm))
    fail("range_mm", "must be the first and last of nodes_mm (or left out)");
  if (j.contains("subdivisions") && (!j["subdivisions"].is_number_integer() || j["subdivisions"].get<int>() != p.subdivisions))
    fail("subdivisions", "must be the number of nodes_mm less one (or left out)");
  if (models::Grid::from_nodes(p.nodes_mm).uniform()) p.nodes_mm.clear();  // the uniform grid, written out
}

// An adaptive design on a fot plan with range_mm and subdivisions (its coarse rows).
Design parse_design(const json& j, const Plan& p) {
  Design d;
  if (!j.contains("design")) return d;
  const json& o = j["design"];
  if (!o.is_object()) fail("design", "must be an object: {\"kind\": \"adaptive\", \"budget_s\": 600, ...}");
  fields::only(o, "design.", {"kind", "budget_s", "target_rms_N", "min_gain", "finest_subdivisions"});
  if (!o.contains("kind") || !o["kind"].is_string()) fail("design.kind", "is required: \"adaptive\" or \"uniform\"");
  const std::string kind = o["kind"].get<std::string>();
  if (kind != "adaptive" && kind != "uniform") fail("design.kind", "must be \"adaptive\" or \"uniform\" (got \"" + kind + "\")");
  if (kind == "uniform") {
    if (o.size() > 1) fail("design", "of kind \"uniform\" takes no other field (every row of the grid is driven)");
    return d;
  }
  d.adaptive = true;
  if (!p.nodes_mm.empty()) fail("design", "needs range_mm and subdivisions (its coarse rows), not nodes_mm: it places the other rows itself");
  if (p.repeats != 1) fail("repeats", "must be 1 with an adaptive design (it drives each row it chooses once)");
  if (p.subdivisions < 2 || p.subdivisions > 96)
    fail("subdivisions", "must be from 2 to 96 with an adaptive design (the coarse rows: the curvature needs 3 nodes, the finest grid doubles them)");
  // A row's top and its bottom are read within a quarter of the finest step (OnlineFot), and the
  // frame arrives within the in-position tolerance (0.01 mm by default): a step of at least
  // kMinFineStep_mm keeps both readable.
  const double span = p.hi_mm - p.lo_mm;
  int finest = 2 * p.subdivisions;
  while (finest * 2 <= 96 && finest < 8 * p.subdivisions && span / (finest * 2) >= kMinFineStep_mm) finest *= 2;
  d.finest_subdivisions = fields::integer(o, "finest_subdivisions", finest, "design.");
  int halved = p.subdivisions;
  while (halved < d.finest_subdivisions) halved *= 2;
  if (halved != d.finest_subdivisions || d.finest_subdivisions == p.subdivisions)
    fail("design.finest_subdivisions",
         "must be subdivisions (" + std::to_string(p.subdivisions) + ") doubled once or more: a row halves a band of the grid, so its top lies on it");
  if (span / d.finest_subdivisions < kMinFineStep_mm) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "gives a step of %.4g mm, below %.3g mm: a row's top and bottom are read within a quarter step of their node",
                  span / d.finest_subdivisions, kMinFineStep_mm);
    fail("design.finest_subdivisions", buf);
  }
  if (!o.contains("budget_s")) fail("design.budget_s", "is required: the rig seconds the rows may take");
  d.budget_s = number(o, "budget_s", 0.0, "design.");
  d.target_rms_N = number(o, "target_rms_N", 0.0, "design.");
  d.min_gain = number(o, "min_gain", d.min_gain, "design.");
  const models::Grid g = fot_grid(p);
  double coarse = 0;
  for (int i = 1; i <= g.n; ++i) coarse += row_seconds(p, g.node(i) - p.lo_mm);
  const double first = row_seconds(p, 0.5 * (g.node(1) + g.node(0)) - p.lo_mm);
  if (d.budget_s < coarse + first) {
    char buf[240];
    std::snprintf(buf, sizeof buf, "%.4g s is below the coarse rows (%.4g s for %d) and one row more (%.4g s): nothing left to choose", d.budget_s, coarse, g.n,
                  first);
    fail("design.budget_s", buf);
  }
  return d;
}

void parse_sine(const json& j, Plan& p) {
  p.sine = parse_sine_plan(j, p.sample_rate_hz);
  const double a = p.sine.max_amplitude_mm();
  p.lo_mm = -a;
  p.hi_mm = a;
  p.limits = parse_limits(j.value("limits", json()), -10 * a - 1, 10 * a + 1);
}
}  // namespace

Plan parse_plan(const json& j) {
  if (!j.is_object()) fail("", "must be a JSON object");
  Plan p;
  p.source = j;
  if (!j.contains("kind") || !j["kind"].is_string()) fail("kind", "is required: \"fot\", \"waveform\" or \"sine\"");
  const std::string kind = j["kind"].get<std::string>();
  const auto parsed_kind = domain::campaign_kind_from(kind);
  if (!parsed_kind) fail("kind", "must be \"fot\", \"waveform\" or \"sine\" (got \"" + kind + "\")");
  p.kind = *parsed_kind;
  static const char* common[] = {"kind", "ramp_rate_mm_s", "dwell_s", "sample_rate_hz", "limits", "name", "specimen", "notes"};
  // What the lab records with the campaign (the report, the lists and the exports show them).
  for (const char* field : {"specimen", "notes"}) {  // checked as a later change is (db/campaign_record.hpp)
    if (!j.contains(field)) continue;
    if (!j[field].is_string()) fail(field, "must be text");
    if (const auto problem = domain::record_field_problem(field, j[field].get<std::string>())) fail(field, *problem);
  }
  auto known = [&](const std::vector<std::string>& extra) {
    for (const auto& [k, _] : j.items()) {
      bool ok = std::find(std::begin(common), std::end(common), k) != std::end(common);
      for (const auto& e : extra) ok = ok || e == k;
      if (!ok) fail(k, std::string("is not a field of a ") + domain::to_string(p.kind) + " plan");
    }
  };
  p.ramp_rate_mm_s = number(j, "ramp_rate_mm_s", 0.5);
  p.dwell_s = number(j, "dwell_s", 0.0);
  p.sample_rate_hz = number(j, "sample_rate_hz", 1000.0);
  if (p.kind == domain::CampaignKind::fot) {
    known({"range_mm", "subdivisions", "nodes_mm", "repeats", "training_cycles", "training", "validation", "plateaus_mm", "design"});
    if (j.contains("nodes_mm")) {
      parse_nodes(j, p);
    } else {
      if (!j.contains("range_mm")) fail("range_mm", "is required");
      std::tie(p.lo_mm, p.hi_mm) = pair_of(j["range_mm"], "range_mm");
      if (!j.contains("subdivisions")) fail("subdivisions", "is required");
      p.subdivisions = fields::integer(j, "subdivisions", 0);
    }
    p.repeats = fields::integer(j, "repeats", 1);
    p.training = parse_training(j);
    p.limits = parse_limits(j.value("limits", json()), p.lo_mm, p.hi_mm);
    if (p.lo_mm < p.limits.displacement_min_mm || p.hi_mm > p.limits.displacement_max_mm) fail("range_mm", "must lie inside limits.displacement_mm");
    p.validation = parse_validation(j, p);
    p.plateaus_mm = parse_plateaus(j, p);
    p.design = parse_design(j, p);
  } else if (p.kind == domain::CampaignKind::waveform) {
    known({"points_mm"});
    if (!j.contains("points_mm") || !j["points_mm"].is_array() || j["points_mm"].size() < 2)
      fail("points_mm", "must be an array of at least two displacements");
    for (std::size_t k = 0; k < j["points_mm"].size(); ++k) {
      const json& v = j["points_mm"][k];
      if (!v.is_number() || !std::isfinite(v.get<double>())) fail("points_mm[" + std::to_string(k) + "]", "must be a number");
      p.points_mm.push_back(v.get<double>());
    }
    const auto [mn, mx] = std::minmax_element(p.points_mm.begin(), p.points_mm.end());
    p.lo_mm = *mn;
    p.hi_mm = *mx;
    p.limits = parse_limits(j.value("limits", json()), p.lo_mm, p.hi_mm);
    for (std::size_t k = 0; k < p.points_mm.size(); ++k)
      if (p.points_mm[k] < p.limits.displacement_min_mm || p.points_mm[k] > p.limits.displacement_max_mm)
        fail("points_mm[" + std::to_string(k) + "]", "lies outside limits.displacement_mm");
  } else {
    known({"frequencies_hz", "sweep", "amplitude_mm", "amplitudes_mm", "direction", "settle_cycles", "settle", "measured_cycles", "control", "jump_threshold",
           "resonance", "isolator", "dwell"});
    parse_sine(j, p);
  }
  // Only against a rate the plan wrote: without one, the rig's envelope decides at submission and
  // names its own maximum (check_plan_against), not a default the user never saw.
  const bool own_rate = j.contains("limits") && j["limits"].is_object() && j["limits"].contains("rate_mm_s");
  if (own_rate && p.ramp_rate_mm_s > p.limits.rate_max_mm_s) fail("ramp_rate_mm_s", "is above limits.rate_mm_s");
  if (own_rate && p.validation.enabled && p.validation.rate_mm_s > p.limits.rate_max_mm_s) fail("validation.rate_mm_s", "is above limits.rate_mm_s");
  return p;
}

models::Grid fot_grid(const Plan& p) {
  return p.nodes_mm.empty() ? models::Grid::make(p.lo_mm, p.hi_mm, p.subdivisions) : models::Grid::from_nodes(p.nodes_mm);
}

models::Grid node_grid(const Plan& p) { return p.design.adaptive ? models::Grid::make(p.lo_mm, p.hi_mm, p.design.finest_subdivisions) : fot_grid(p); }

double row_seconds(const Plan& p, double above_mm) { return models::row_seconds(above_mm, p.ramp_rate_mm_s, 2.0 * p.dwell_s + kRowSettle_s); }

}  // namespace hystlab::domain
