#include "hystlab/domain/plan_fields.hpp"

#include <array>
#include <stdexcept>
#include <string>

#include "hystlab/domain/record.hpp"

namespace hystlab::domain {
namespace {
using T = FieldType;
constexpr double kMm = 1e4;  // a displacement the parser takes, either way (mm)

// The form's defaults show the simulated rigs something worth seeing: a 0–4 mm FOT table of an
// SMA spring in about 2 minutes; a sine sweep that crosses the simulated isolator's resonance
// (17.7 Hz) at two amplitudes in about 4 minutes.
// An input of the form, and a field the parser alone reads (-Wmissing-field-initializers wants
// every member of an aggregate written out).
constexpr PlanField input(std::string_view path, std::string_view words, std::string_view unit, double min, double max, FieldType type, std::string_view group,
                          std::string_view name, std::string_view label, std::string_view value, std::string_view placeholder = "", bool optional = false,
                          std::string_view choices = "") {
  return {path, words, unit, min, max, type, group, name, label, value, placeholder, optional, choices};
}
constexpr PlanField field(std::string_view path, std::string_view words, std::string_view unit, double min, double max, FieldType type) {
  return {path, words, unit, min, max, type, "", "", "", "", "", false, ""};
}

// clang-format off
constexpr std::array kFields{
  // ---- the form's inputs, in its order ----
  input("range_mm[0]", "δmin", "mm", -kMm, kMm, T::number, "fot", "lo", "", "0"),
  input("range_mm[1]", "δmax", "mm", -kMm, kMm, T::number, "fot", "hi", "", "4"),
  input("subdivisions", "subdivisions", "", 1, 200, T::integer, "fot", "n", "subdivisions n", "8"),
  input("ramp_rate_mm_s", "ramp rate", "mm/s", 1e-4, 1e3, T::number, "fot", "rate", "", "0.5"),
  input("dwell_s", "dwell", "s", 0, 3600, T::number, "fot", "dwell", "", "0.2"),
  input("training_cycles", "training cycles", "", 0, 1000, T::integer, "fot", "training", "training cycles (at most)", "0"),
  input("training.until.energy_change", "energy change per cycle", "% per cycle", 0, 100, T::percent, "fot", "stable", "train until energy changes less than", "", "all cycles", true),
  input("validation.reversals", "validation reversals", "", 2, 10000, T::integer, "fot", "reversals", "validation reversals (0: none)", "12"),
  input("plateaus_mm", "plateau forces at", "mm", -kMm, kMm, T::list, "fot", "plateaus", "", "", "none", true),
  input("repeats", "repeats", "", 1, 100, T::integer, "fot", "repeats", "", "1"),
  input("sweep.from_hz", "sweep from", "Hz", 1e-3, 1000, T::number, "sine", "fromhz", "", "5"),
  input("sweep.to_hz", "sweep to", "Hz", 1e-3, 1000, T::number, "sine", "tohz", "", "60"),
  input("sweep.steps", "steps", "", 2, 1000, T::integer, "sine", "steps", "steps (log spaced)", "24"),
  input("frequencies_hz", "frequencies", "Hz", 1e-3, 1000, T::list, "sine", "freqs", "or these frequencies", "", "the steps above", true),
  input("direction", "direction", "", 0, 0, T::choice, "sine", "direction", "", "up-down", "", false, "up|down|up-down"),
  input("amplitudes_mm", "base amplitudes (peak)", "mm", 1e-4, 100, T::list, "sine", "amps", "", "0.005, 0.05"),
  input("settle.change", "settle change", "%", 0, 100, T::percent, "sine", "settlechange", "settle until the response changes less than", "2", "settle cycles", true),
  input("settle_cycles", "settle cycles", "", 0, 100000, T::integer, "sine", "settle", "or settle cycles (instead)", "", "until settled", true),
  input("measured_cycles", "measured cycles", "", 1, 100000, T::integer, "sine", "measured", "", "10"),
  input("resonance.half_power_points", "points in the half-power band", "", 3, 100, T::integer, "sine", "respts", "refine the resonance until its half-power band holds", "5", "no refinement", true),
  input("isolator.table", "the isolator's springs: table", "", 1, 1e9, T::integer, "sine", "isotable", "predict with the springs of table #", "", "the rig's springs", true),
  input("control.tolerance", "control tolerance", "%", 0, 100, T::percent, "sine", "tol", "", "5"),
  input("control.warning", "control warning", "%", 0, 1000, T::percent, "sine", "warn", "control warning beyond", "", "daemon's: 10", true),
  input("control.abort", "control abort", "%", 0, 1000, T::percent, "sine", "abortpct", "control abort beyond", "", "daemon's: 30", true),
  input("sample_rate_hz", "sample rate", "Hz", 1, 10000, T::number, "common", "hz", "", "1000"),
  input("limits.displacement_mm[0]", "lower displacement limit", "mm", -kMm, kMm, T::number, "limits", "dlo", "", "", "δmin − 0.5", true),
  input("limits.displacement_mm[1]", "upper displacement limit", "mm", -kMm, kMm, T::number, "limits", "dhi", "", "", "δmax + 0.5", true),
  input("limits.force_N", "force limit", "N", 1e-6, 1e7, T::number, "limits", "force", "", "400", "rig's", true),
  input("limits.rate_mm_s", "rate limit", "mm/s", 1e-6, 1e4, T::number, "limits", "ratelim", "", "", "rig's", true),
  input("specimen", "specimen", "", 0, static_cast<double>(kSpecimenMaxChars), T::text, "record", "specimen", "", "", "e.g. NiTi spring S-07", true),
  input("notes", "notes", "", 0, static_cast<double>(kNotesMaxChars), T::text, "record", "notes", "", "", "operator, set-up, anything seen", true),
  // ---- the parser's other fields (a pasted plan may give them) ----
  field("limits.safe_position_mm", "safe position", "mm", -kMm, kMm, T::number),
  field("limits.safe_rate_mm_s", "safe rate", "mm/s", 1e-6, 1e3, T::number),
  field("training.max_cycles", "training cycles", "", 1, 1000, T::integer),
  field("training.until.peak_force_change", "peak force change per cycle", "%", 0, 100, T::percent),
  field("training.until.consecutive", "cycles in a row", "", 1, 100, T::integer),
  field("design.budget_s", "design budget", "s", 1, 1e7, T::number),
  field("design.target_rms_N", "design target (held-out RMS)", "N", 0, 1e6, T::number),
  field("design.min_gain", "design gain at least", "", 1e-4, 0.5, T::number),
  field("design.finest_subdivisions", "finest subdivisions", "", 2, 192, T::integer),
  field("validation.rate_mm_s", "validation rate", "mm/s", 1e-4, 1e3, T::number),
  field("sweep.rate_oct_min", "sweep rate", "oct/min", 1e-3, 100, T::number),
  field("sweep.rate_hz_s", "sweep rate", "Hz/s", 1e-4, 100, T::number),
  field("amplitude_mm", "base amplitude (peak)", "mm", 1e-4, 100, T::number),
  field("settle.consecutive", "settle windows in a row", "", 1, 100, T::integer),
  field("settle.min_cycles", "settle cycles at least", "", 0, 100000, T::integer),
  field("settle.max_cycles", "settle cycles at most", "", 1, 100000, T::integer),
  field("control.converge", "control convergence", "%", 0, 100, T::percent),
  field("control.gain", "control gain", "", 0.05, 1, T::number),
  field("control.window_cycles", "control window", "cycles", 1, 1000, T::integer),
  field("control.max_windows", "control windows at most", "", 1, 1000, T::integer),
  field("control.max_drive_ratio", "drive at most", "× the demand", 1, 100, T::number),
  field("control.start_level", "start level", "", 0.05, 1, T::number),
  field("control.abort_windows", "abort windows in a row", "", 1, 100, T::integer),
  field("control.pretest_level", "loop check level", "× the smallest amplitude", 0, 1, T::number),
  field("jump_threshold", "jump threshold", "%", 0, 100, T::percent),
  field("resonance.max_steps", "resonance steps added at most", "", 1, 1000, T::integer),
  field("dwell.frequency_hz", "dwell frequency", "Hz", 1e-3, 1000, T::number),
  field("dwell.cycles", "dwell cycles", "", 1, 100000000, T::integer),
  field("dwell.phase_deg", "dwell phase", "°", -180, 180, T::number),
  field("dwell.tolerance_deg", "dwell phase tolerance", "°", 0.1, 90, T::number),
  field("dwell.max_windows", "windows to find the phase at most", "", 1, 10000, T::integer),
};
// clang-format on
}  // namespace

const char* to_string(FieldType t) noexcept {
  switch (t) {
    case T::number:
      return "number";
    case T::integer:
      return "integer";
    case T::percent:
      return "percent";
    case T::list:
      return "list";
    case T::text:
      return "text";
    case T::choice:
      return "choice";
  }
  return "?";
}

std::span<const PlanField> plan_fields() noexcept { return kFields; }

const PlanField& plan_field(std::string_view path) {
  for (const PlanField& f : kFields)
    if (f.path == path) return f;
  throw std::logic_error("plan field " + std::string(path) + " is not in the table (protocols/domain/src/plan_fields.cpp)");
}

nlohmann::json plan_form_json() {
  nlohmann::json fields = nlohmann::json::array();
  for (const PlanField& f : kFields) {
    nlohmann::json j{{"path", f.path}, {"words", f.words}, {"unit", f.unit}, {"type", to_string(f.type)}, {"optional", f.optional}};
    if (f.type != T::choice) j["min"] = f.min, j["max"] = f.max;
    if (!f.group.empty())
      j["group"] = f.group, j["input"] = f.input, j["label"] = f.label.empty() ? f.words : f.label, j["value"] = f.value, j["placeholder"] = f.placeholder;
    if (f.type == T::choice) {
      nlohmann::json choices = nlohmann::json::array();
      for (std::string_view rest = f.choices; !rest.empty();) {
        const std::size_t bar = rest.find('|');
        choices.push_back(rest.substr(0, bar));
        rest = bar == std::string_view::npos ? std::string_view() : rest.substr(bar + 1);
      }
      j["choices"] = choices;
    }
    fields.push_back(std::move(j));
  }
  return {{"fields", fields}};
}

}  // namespace hystlab::domain
