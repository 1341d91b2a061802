#include "hystlab/domain/sine_plan.hpp"

#include <algorithm>
#include <cmath>

#include "field_reader.hpp"

namespace hystlab::domain {
using nlohmann::json;

const char* to_string(SweepDirection d) noexcept {
  switch (d) {
    case SweepDirection::up:
      return "up";
    case SweepDirection::down:
      return "down";
    case SweepDirection::up_down:
      return "up-down";
  }
  return "?";
}

double SinePlan::max_amplitude_mm() const { return amplitudes_mm.empty() ? 0.0 : *std::max_element(amplitudes_mm.begin(), amplitudes_mm.end()); }

namespace {
std::vector<double> frequency_list(const json& a) {
  if (!a.is_array() || a.empty() || a.size() > 1000) fields::fail("frequencies_hz", "must be an array of 1 to 1000 frequencies");
  std::vector<double> out;
  for (std::size_t k = 0; k < a.size(); ++k) {
    out.push_back(fields::element(a[k], "frequencies_hz", "frequencies_hz[" + std::to_string(k) + "]"));
  }
  std::sort(out.begin(), out.end());  // the direction says the order
  if (std::adjacent_find(out.begin(), out.end()) != out.end()) fields::fail("frequencies_hz", "must not repeat a frequency");
  return out;
}

void parse_sweep(const json& s, SinePlan& p) {
  if (!s.is_object()) fields::fail("sweep", "must be an object: {\"from_hz\": 5, \"to_hz\": 80, \"steps\": 24} or {..., \"rate_oct_min\": 2}");
  fields::only(s, "sweep.", {"from_hz", "to_hz", "steps", "spacing", "rate_oct_min", "rate_hz_s"});
  if (!s.contains("from_hz") || !s.contains("to_hz")) fields::fail("sweep", "needs from_hz and to_hz");
  p.from_hz = fields::number(s, "from_hz", 0, "sweep.");
  p.to_hz = fields::number(s, "to_hz", 0, "sweep.");
  if (!(p.to_hz > p.from_hz)) fields::fail("sweep.to_hz", "must be above sweep.from_hz");
  const bool rate = s.contains("rate_oct_min") || s.contains("rate_hz_s");
  if (rate) {
    if (s.contains("rate_oct_min") && s.contains("rate_hz_s")) fields::fail("sweep.rate_hz_s", "and sweep.rate_oct_min: give one rate");
    if (s.contains("steps") || s.contains("spacing")) fields::fail("sweep.steps", "is for a stepped sweep; a continuous one has a rate only");
    p.continuous = true;
    p.rate_oct_min = fields::number(s, "rate_oct_min", 0, "sweep.");
    p.rate_hz_s = fields::number(s, "rate_hz_s", 0, "sweep.");
    return;
  }
  const int n = fields::integer(s, "steps", 24, "sweep.");
  const std::string spacing = s.value("spacing", std::string("log"));
  if (spacing != "log" && spacing != "linear") fields::fail("sweep.spacing", "must be \"log\" or \"linear\"");
  for (int k = 0; k < n; ++k) {
    const double u = k / double(n - 1);
    p.frequencies_hz.push_back(spacing == "log" ? p.from_hz * std::pow(p.to_hz / p.from_hz, u) : p.from_hz + (p.to_hz - p.from_hz) * u);
  }
}

std::vector<double> amplitudes(const json& j) {
  if (j.contains("amplitude_mm") == j.contains("amplitudes_mm"))
    fields::fail("amplitudes_mm", "or amplitude_mm: exactly one is required (the base amplitude, peak, mm)");
  if (j.contains("amplitude_mm")) return {fields::number(j, "amplitude_mm", 0)};
  const json& a = j["amplitudes_mm"];
  if (!a.is_array() || a.empty() || a.size() > 20) fields::fail("amplitudes_mm", "must be an array of 1 to 20 base amplitudes (mm)");
  std::vector<double> out;
  for (std::size_t k = 0; k < a.size(); ++k) {
    out.push_back(fields::element(a[k], "amplitudes_mm", "amplitudes_mm[" + std::to_string(k) + "]"));
  }
  return out;
}

SineSettle parse_settle(const json& j) {
  SineSettle s;
  if (j.contains("settle") && j.contains("settle_cycles")) fields::fail("settle", "and settle_cycles: give one of them");
  if (!j.contains("settle")) {
    s.cycles = fields::integer(j, "settle_cycles", 10);
    return s;
  }
  const json& b = j["settle"];
  if (!b.is_object()) fields::fail("settle", "must be an object: {\"change\": \"2 %\", \"consecutive\": 2, \"min_cycles\": 30, \"max_cycles\": 400}");
  fields::only(b, "settle.", {"change", "consecutive", "min_cycles", "max_cycles"});
  s.until = true;
  s.cycles = 0;
  s.change_pct = fields::percent(b, "change", s.change_pct, "settle.");
  s.consecutive = fields::integer(b, "consecutive", s.consecutive, "settle.");
  s.min_cycles = fields::integer(b, "min_cycles", s.min_cycles, "settle.");
  s.max_cycles = fields::integer(b, "max_cycles", s.max_cycles, "settle.");
  if (s.max_cycles < s.min_cycles) fields::fail("settle.max_cycles", "must be at least settle.min_cycles");
  return s;
}

SineDwell parse_dwell(const json& b) {
  if (!b.is_object()) fields::fail("dwell", "must be an object: {\"frequency_hz\": 17, \"cycles\": 2000, \"track\": \"phase\"}");
  fields::only(b, "dwell.", {"frequency_hz", "cycles", "track", "phase_deg", "tolerance_deg", "max_windows"});
  if (!b.contains("frequency_hz") || !b.contains("cycles")) fields::fail("dwell", "needs frequency_hz (where it starts) and cycles (how long it holds)");
  SineDwell d;
  d.on = true;
  d.frequency_hz = fields::number(b, "frequency_hz", 0, "dwell.");
  d.cycles = fields::integer(b, "cycles", 0, "dwell.");
  const std::string track = b.contains("track") && b["track"].is_string() ? b["track"].get<std::string>() : b.contains("track") ? "?" : "none";
  if (track != "phase" && track != "none") fields::fail("dwell.track", "must be \"phase\" (the frequency follows the phase) or \"none\" (held)");
  d.track_phase = track == "phase";
  d.phase_deg = fields::number(b, "phase_deg", d.phase_deg, "dwell.");
  d.tolerance_deg = fields::number(b, "tolerance_deg", d.tolerance_deg, "dwell.");
  d.max_windows = fields::integer(b, "max_windows", d.max_windows, "dwell.");
  return d;
}

SineResonance parse_resonance(const json& j, bool continuous) {
  SineResonance r;
  if (!j.contains("resonance")) return r;
  const json& b = j["resonance"];
  if (b.is_boolean()) {
    r.refine = b.get<bool>();
  } else {
    if (!b.is_object()) fields::fail("resonance", "must be an object ({\"half_power_points\": 5, \"max_steps\": 40}), true or false");
    fields::only(b, "resonance.", {"half_power_points", "max_steps"});
    r.refine = true;
    r.half_power_points = fields::integer(b, "half_power_points", r.half_power_points, "resonance.");
    r.max_steps = fields::integer(b, "max_steps", r.max_steps, "resonance.");
  }
  if (r.refine && continuous) fields::fail("resonance", "refines a stepped sweep's steps; a continuous sweep has none (give steps or frequencies_hz)");
  return r;
}

SineControl parse_control(const json& j) {
  SineControl c;
  if (!j.contains("control")) return c;
  const json& b = j["control"];
  if (b.is_boolean()) {
    c.closed = b.get<bool>();
    return c;
  }
  if (!b.is_object()) fields::fail("control", "must be an object ({\"tolerance\": \"5 %\", ...}) or false (open loop)");
  fields::only(b, "control.",
               {"tolerance", "warning", "abort", "converge", "gain", "window_cycles", "max_windows", "max_drive_ratio", "start_level", "abort_windows",
                "pretest_level"});
  c.tolerance_pct = fields::percent(b, "tolerance", c.tolerance_pct, "control.");
  c.converge_pct = fields::percent(b, "converge", std::min(c.converge_pct, c.tolerance_pct), "control.");
  if (c.converge_pct > c.tolerance_pct) fields::fail("control.converge", "must be at most control.tolerance");
  c.warning_pct = fields::percent(b, "warning", std::max(c.warning_pct, c.tolerance_pct), "control.");
  c.abort_pct = fields::percent(b, "abort", std::max(c.abort_pct, c.warning_pct), "control.");
  if (c.warning_pct < c.tolerance_pct) fields::fail("control.warning", "must be at least control.tolerance");
  if (c.abort_pct <= c.warning_pct) fields::fail("control.abort", "must be above control.warning");
  c.gain = fields::number(b, "gain", c.gain, "control.");
  c.window_cycles = fields::integer(b, "window_cycles", c.window_cycles, "control.");
  c.max_windows = fields::integer(b, "max_windows", c.max_windows, "control.");
  c.max_drive_ratio = fields::number(b, "max_drive_ratio", c.max_drive_ratio, "control.");
  c.start_level = fields::number(b, "start_level", c.start_level, "control.");
  c.abort_windows = fields::integer(b, "abort_windows", c.abort_windows, "control.");
  c.pretest_level = fields::number(b, "pretest_level", c.pretest_level, "control.");
  return c;
}
}  // namespace

SinePlan parse_sine_plan(const json& j, double sample_rate_hz) {
  SinePlan p;
  const int given = static_cast<int>(j.contains("frequencies_hz")) + static_cast<int>(j.contains("sweep")) + static_cast<int>(j.contains("dwell"));
  if (given > 1)
    fields::fail(j.contains("dwell") ? "dwell" : "frequencies_hz", j.contains("dwell") ? "or a sweep: give one of them" : "or sweep: give one of them");
  if (given == 0) fields::fail("sweep", "is required (or frequencies_hz, or dwell): {\"from_hz\": 5, \"to_hz\": 80, \"steps\": 24}");
  if (j.contains("frequencies_hz")) {
    p.frequencies_hz = frequency_list(j["frequencies_hz"]);
  } else if (j.contains("dwell")) {
    p.dwell = parse_dwell(j["dwell"]);
    p.frequencies_hz = {p.dwell.frequency_hz};
    if (j.contains("direction")) fields::fail("direction", "is for a sweep; a dwell has none");
  } else {
    parse_sweep(j["sweep"], p);
  }
  if (j.contains("direction")) {
    const json& d = j["direction"];
    const std::string v = d.is_string() ? d.get<std::string>() : "";
    if (v == "up")
      p.direction = SweepDirection::up;
    else if (v == "down")
      p.direction = SweepDirection::down;
    else if (v == "up-down")
      p.direction = SweepDirection::up_down;
    else
      fields::fail("direction", "must be \"up\", \"down\" or \"up-down\"");
  }
  p.amplitudes_mm = amplitudes(j);
  p.settle = parse_settle(j);
  p.measured_cycles = fields::integer(j, "measured_cycles", 10);
  p.control = parse_control(j);
  p.jump_threshold_pct = fields::percent(j, "jump_threshold", p.jump_threshold_pct, "");
  p.resonance = parse_resonance(j, p.continuous);
  if (p.resonance.refine && p.dwell.on) fields::fail("resonance", "refines a sweep's steps; a dwell has none (it tracks the phase)");
  if (j.contains("isolator")) {
    if (!j["isolator"].is_object())
      fields::fail("isolator", "must be an object: {\"table\": 7} (a stored table's id), with mass_kg, springs and damping_N_s_per_m if not the rig's");
    // A stored table's id, read here with the form's bounds (a table document is the daemon's to read).
    if (j["isolator"].contains("table") && j["isolator"]["table"].is_number()) (void)fields::integer(j["isolator"], "table", 0, "isolator.");
    p.isolator = j["isolator"];
  }
  if (p.highest_hz() > sample_rate_hz / 8)
    fields::fail(
        p.dwell.on                            ? "dwell.frequency_hz"
        : p.continuous || j.contains("sweep") ? "sweep.to_hz"
                                              : "frequencies_hz",
        "must stay below sample_rate_hz / 8 (at least 8 samples a cycle): " + plan_number(p.highest_hz()) + " Hz at " + plan_number(sample_rate_hz) + " Hz");
  return p;
}

std::vector<SweepPass> sweep_passes(const SinePlan& p) {
  std::vector<SweepPass> out;
  for (const double a : p.amplitudes_mm) {
    if (p.direction != SweepDirection::down) out.push_back({a, true});
    if (p.direction != SweepDirection::up) out.push_back({a, false});
  }
  return out;
}

std::vector<double> pass_frequencies(const SinePlan& p, const SweepPass& pass) {
  std::vector<double> f = p.frequencies_hz;
  if (!pass.up) std::reverse(f.begin(), f.end());
  return f;
}

namespace {
// Seconds a continuous pass takes to sweep from a to b.
double continuous_seconds(const SinePlan& p) {
  if (p.rate_oct_min > 0) return std::log2(p.to_hz / p.from_hz) / p.rate_oct_min * 60.0;
  return (p.to_hz - p.from_hz) / p.rate_hz_s;
}
}  // namespace

double step_nominal_s(const SinePlan& p, double f) {
  // The control windows (each with its cycle of transient) from a step's start to the convergence
  // band when the table's response is as learnt: a step starts at the drive learnt at its
  // frequency, about 10 % off where the response changes fastest (the isolator's resonance), and
  // the error shrinks by (1 − gain) a window.
  const SineControl& c = p.control;
  const double e0 = 0.1, tol = c.converge_pct / 100;
  const int windows = e0 <= tol ? 1 : 1 + static_cast<int>(std::ceil(std::log(tol / e0) / std::log(std::max(1e-9, 1 - c.gain))));
  const int control = c.closed ? std::min(windows, c.max_windows) * (c.window_cycles + 1) : 0;
  const int settle = p.settle.until ? p.settle.min_cycles + (p.settle.consecutive + 1) * std::max(1, p.control.window_cycles) : p.settle.cycles;
  return (control + settle + p.measured_cycles) / f;
}

bool has_pretest(const SinePlan& p) { return p.control.closed && p.control.pretest_level > 0 && !p.continuous && !p.dwell.on && p.frequencies_hz.size() >= 2; }

std::vector<double> pretest_frequencies(const SinePlan& p) {
  if (!has_pretest(p)) return {};
  std::vector<double> f = p.frequencies_hz;
  std::sort(f.begin(), f.end());
  f.erase(std::unique(f.begin(), f.end()), f.end());
  return f;
}

double pretest_nominal_s(const SinePlan& p) {
  double s = 0;
  for (const double f : pretest_frequencies(p)) s += 2.0 * (p.control.window_cycles + 1) / f;
  return s;
}

double nominal_duration_s(const SinePlan& p) {
  const auto passes = sweep_passes(p);
  if (p.dwell.on) return static_cast<double>(passes.size()) * (step_nominal_s(p, p.dwell.frequency_hz) + p.dwell.cycles / p.dwell.frequency_hz);
  if (p.continuous) return static_cast<double>(passes.size()) * (continuous_seconds(p) + step_nominal_s(p, p.from_hz) - p.measured_cycles / p.from_hz);
  double per_pass = 0;
  for (const double f : p.frequencies_hz) per_pass += step_nominal_s(p, f);
  return pretest_nominal_s(p) + static_cast<double>(passes.size()) * per_pass;
}

std::size_t step_count(const SinePlan& p) {
  const std::size_t passes = sweep_passes(p).size();
  if (p.dwell.on) return passes * static_cast<std::size_t>(std::max(1, (p.dwell.cycles + p.measured_cycles - 1) / p.measured_cycles));
  if (!p.continuous) return passes * p.frequencies_hz.size();
  // cycles in a pass: ∫ f dt over the pass
  const double cycles =
      p.rate_oct_min > 0 ? (p.to_hz - p.from_hz) * 60.0 / (p.rate_oct_min * std::log(2.0)) : (p.to_hz * p.to_hz - p.from_hz * p.from_hz) / (2 * p.rate_hz_s);
  return passes * static_cast<std::size_t>(std::max(1.0, std::floor(cycles / p.measured_cycles)));
}

}  // namespace hystlab::domain
