#include "event_text.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <variant>
#include <vector>

#include "hystlab/domain/events.hpp"

namespace hystlab::cli {
namespace event_words {  // named: the CLI is built in batches (unity), beside other files' helpers
using nlohmann::json;

// Four significant digits; a whole number as it is (502 samples, not 502.0 nor 5.02e+02).
std::string g(double v) {
  char b[32];
  if (v == 0) return "0";  // never "-0"
  if (v == std::floor(v) && std::fabs(v) < 1e15)
    std::snprintf(b, sizeof b, "%.0f", v);
  else
    std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

// A field as a number ("%.4g"), or "?" when the detail has none.
std::string num(const json& d, const char* key) {
  const auto it = d.find(key);
  return it != d.end() && it->is_number() ? g(it->get<double>()) : "?";
}

// "1 sample", "3 samples"
std::string count(double k, const std::string& one, const std::string& many = "") { return g(k) + " " + (k == 1 ? one : many.empty() ? one + "s" : many); }

// A number, or "?" for a value the event did not carry (NaN: missing, or stored as null).
std::string n(double v) { return std::isnan(v) ? "?" : g(v); }
std::string n(std::int64_t v) { return g(static_cast<double>(v)); }
std::string n(const std::optional<double>& v) { return v ? n(*v) : "?"; }

std::string range(const std::array<double, 2>& r, const char* unit) { return n(r[0]) + ".." + n(r[1]) + " " + unit; }

std::string signed_pct(const std::optional<double>& v) {
  if (!v) return "";
  return std::string(" (") + (*v > 0 ? "+" : "") + g(*v) + " %)";
}

// One sentence per kind (domain/events.hpp): a field renamed there fails to build here.
std::string say(const domain::LimitsEvent& d) {
  return "displacement " + range(d.displacement_mm, "mm") + ", force up to " + n(d.force_N) + " N, rate up to " + n(d.rate_mm_s) + " mm/s; safe position " +
         n(d.safe_position_mm) + " mm at " + n(d.safe_rate_mm_s) + " mm/s; in position within " + n(d.in_position_mm) + " mm";
}

std::string say(const domain::EnvelopeEvent& d) {
  if (d.stroke_mm)
    return "the rig's envelope: stroke " + range(*d.stroke_mm, "mm") + ", force " + n(d.force_N) + " N, speed " + n(d.speed_mm_s) + " mm/s, acceleration " +
           n(d.accel_mm_s2) + " mm/s²";
  return "the rig's envelope: base displacement " + n(d.displacement_mm) + " mm, velocity " + n(d.velocity_mm_s) + " mm/s, acceleration " + n(d.accel_g) +
         " g, " + (d.frequency_hz ? range(*d.frequency_hz, "Hz") : "? Hz");
}

std::string say(const domain::FitEvent& d) {
  const json overall = d.accuracy.is_object() ? d.accuracy.value("overall", json::object()) : json::object();
  return "partial table (" + n(d.nodes) + " of " + n(d.required) + " nodes): RMS " + num(overall, "rms_N") + " N, max " + num(overall, "max_N") +
         " N on the run so far";
}

std::string say(const domain::QualityEvent& d) {
  std::string s = "run " + n(d.run) + ": " + count(static_cast<double>(d.samples), "sample") + " in " + n(d.rig_seconds) + " s of rig time (" + n(d.rate_hz) +
                  " Hz; " + n(d.expected_rate_hz) + " Hz expected)";
  std::string issues;
  const auto add = [&issues](const std::string& what) { issues += (issues.empty() ? "" : ", ") + what; };
  if (d.gaps == 1)
    add("1 gap of " + g(1e3 * d.gap_total_s) + " ms");
  else if (d.gaps > 1)
    add(count(static_cast<double>(d.gaps), "gap") + " (" + g(1e3 * d.gap_total_s) + " ms in all, the longest " + g(1e3 * d.longest_gap_s) + " ms)");
  struct Counted {
    std::int64_t value;
    const char *one, *many;
  };
  const Counted counted[] = {{d.lost_samples, "sample lost", "samples lost"},   {d.missed_deadlines, "missed deadline", "missed deadlines"},
                             {d.late_wakeups, "late wake-up", "late wake-ups"}, {d.dropped, "sample dropped by the writer", "samples dropped by the writer"},
                             {d.io_errors, "I/O error", "I/O errors"},          {d.timeouts, "timeout", "timeouts"},
                             {d.reconnects, "reconnection", "reconnections"}};
  for (const Counted& c : counted)
    if (c.value > 0) add(count(static_cast<double>(c.value), c.one, c.many));
  return s + (issues.empty() ? ", nothing lost" : ": " + issues);
}

std::string say(const domain::ShakedownEvent& d) {
  return "cycle " + n(d.cycle) + ": peak force " + n(d.peak_force_N) + " N" + signed_pct(d.peak_change_pct) + ", energy " + n(d.energy_Nmm) + " N·mm" +
         signed_pct(d.energy_change_pct) + ", damping ratio " + n(d.damping_ratio) + (d.stable ? ", stable" : "");
}

std::string say(const domain::RetakeEvent& d) {
  if (d.frequency_hz) return "at " + n(d.frequency_hz) + " Hz, attempt " + (d.attempt ? n(*d.attempt) : "?") + ": " + d.why;
  std::string rows;
  for (const std::int64_t r : d.rows.value_or(std::vector<std::int64_t>{})) rows += (rows.empty() ? "" : ", ") + std::to_string(r);
  return "row(s) " + rows + " again (round " + (d.round ? n(*d.round) : "?") + "): " + d.why;
}

std::string say(const domain::DesignEvent& d) {
  const std::string state = n(d.rows) + " rows, estimated held-out RMS " + n(d.estimated_rms_N) + " N (noise " + n(d.noise_N) + " N), " + n(d.spent_s) +
                            " of " + n(d.budget_s) + " s";
  if (!d.stopped.empty()) return state + ": design stops (" + d.stopped + ")";
  return state + ": next row to " + n(d.alpha_mm) + " mm (" + n(d.next_s) + " s), " + d.why;
}

// How the step was reached from the one before (sine_step's change).
std::string reached(const domain::SineStepEvent& d) {
  if (d.change == "glide") return ", glided to over " + n(d.glide_cycles) + " frequencies";
  if (d.change == "burst") return ", the drive's phase moved " + n(d.shift_deg) + "° across the resonance";
  if (d.change == "jump") return ", jumped to";
  return "";
}

std::string say(const domain::SineStepEvent& d) {
  return "step " + n(d.k) + " of " + n(d.of) + " (pass " + n(d.pass) + " of " + n(d.passes) + "): " + n(d.frequency_hz) + " Hz, " + n(d.amplitude_mm) + " mm " +
         d.direction + ", drive " + n(d.drive_mm) + " mm" + reached(d) + "; about " + n(d.eta_s) + " s left";
}

std::string say(const domain::TransmissibilityEvent& d) {
  return "point " + n(d.k) + " of " + n(d.of) + ": " + n(d.frequency_hz) + " Hz, " + n(d.amplitude_mm) + " mm " + d.direction + ": ratio " + n(d.ratio) +
         ", phase " + n(d.phase_rad) + " rad, control error " + n(d.control_error_pct) + " %";
}

std::string say(const domain::SweepDoneEvent& d) {
  std::string s = n(d.points) + " of " + n(d.of) + " points in " + n(d.seconds) + " s (" + n(d.nominal_seconds) + " s planned)";
  if (d.warnings > 0) s += ", " + count(static_cast<double>(d.warnings), "control warning");
  if (!d.predicted_with.empty()) s += "; predicted with " + d.predicted_with;
  return s;
}

std::string base_error(double f, double base, double demand, double error) {
  return "at " + n(f) + " Hz: base " + n(base) + " mm for a demand of " + n(demand) + " mm (error " + n(error) + " %";
}
std::string say(const domain::ControlAbortEvent& d) {
  return base_error(d.frequency_hz, d.base_mm, d.demand_mm, d.error_pct) + "): stopped, drive " + n(d.drive_mm) + " mm";
}
std::string say(const domain::ControlWarningEvent& d) { return base_error(d.frequency_hz, d.base_mm, d.demand_mm, d.error_pct) + ", " + d.band + ")"; }
std::string say(const domain::ControlUnreachedEvent& d) {
  return "at " + n(d.frequency_hz) + " Hz: the demand " + n(d.demand_mm) + " mm not reached in " + count(static_cast<double>(d.windows), "window") +
         " (error " + n(d.error_pct) + " %, drive " + n(d.drive_mm) + " mm" + (d.limited ? ", at its limit" : "") + ")" + (d.while_ ? "; measured anyway" : "");
}
std::string say(const domain::UnsettledEvent& d) {
  return "at " + n(d.frequency_hz) + " Hz: not settled after " + n(d.cycles) + " cycles (still changing " + n(d.change_pct) + " %)";
}
std::string say(const domain::PretestEvent& d) {
  std::string s = "loop check: " + count(static_cast<double>(d.frequencies), "frequency", "frequencies") + " at " + n(d.level_mm) + " mm in " + n(d.seconds) +
                  " s, " + count(static_cast<double>(d.windows), "window") + "; the table's response " + n(d.response_min) + " to " + n(d.response_max) +
                  " of the drive";
  return d.unsettled > 0 ? s + " (" + n(d.unsettled) + " not settled)" : s;
}
std::string say(const domain::DwellEvent& d) {
  std::string s = "pass " + n(d.pass) + ": dwell at " + n(d.amplitude_mm) + " mm";
  if (d.track != "phase") return s + ", " + n(d.frequency_hz) + " Hz for " + count(static_cast<double>(d.cycles), "cycle");
  if (!d.locked)
    return s + ": the phase " + n(d.target_deg) + "° not found in " + count(static_cast<double>(d.windows), "window") + " (from " + n(d.start_hz) + " Hz)";
  return s + " held at " + n(d.target_deg) + "° (mean " + n(d.phase_deg) + "°) for " + count(static_cast<double>(d.cycles), "cycle") + ", ending at " +
         n(d.frequency_hz) + " Hz (from " + n(d.start_hz) + " Hz); " + n(d.out_of_tolerance) + " windows beyond the tolerance";
}

std::string say(const domain::ResonanceUnresolvedEvent& d) {
  return "pass " + n(d.pass) + ": the resonance near " + n(d.frequency_hz) + " Hz not resolved (" + n(d.band_points) + " of " + n(d.wanted) +
         " points in its half-power band, " + count(static_cast<double>(d.added), "step") + " added): " + d.why;
}

// The specimen and notes as changed (db/campaign_record.hpp): the notes on one line.
std::string say(const domain::RecordEvent& d) {
  std::string notes = d.notes;
  for (char& c : notes) c = c == '\n' ? ' ' : c;
  return "the record changed: specimen " + (d.specimen.empty() ? "(none)" : d.specimen) + "; notes " + (notes.empty() ? "(none)" : notes);
}

std::string say(const domain::ValidationEvent& d) {
  return "run " + n(d.run) + ": " + n(d.reversals) + " reversals from seed " + std::to_string(d.seed) + " (" + d.why + ")";
}
std::string say(const domain::RecommendationEvent& d) { return "table " + n(d.table) + " (" + d.method + ", n = " + n(d.n) + "): " + d.why; }
std::string say(const domain::TrainingEvent& d) { return count(static_cast<double>(d.cycles), "cycle") + (d.stable ? ", stable: " : ", not stable: ") + d.why; }
std::string say(const domain::GapEvent& d) { return "no samples from " + n(d.from_s) + " s to " + n(d.to_s) + " s of rig time (" + n(d.length_ms) + " ms)"; }
std::string say(const domain::GapsEvent& d) {
  return count(static_cast<double>(d.count), "gap") + " in the data, " + n(d.total_ms) + " ms in all, the longest " + n(d.longest_ms) + " ms";
}
std::string say(const domain::SafeEvent& d) {
  return "at the safe position: " + n(d.position_mm) + " mm (target " + n(d.target_mm) + " mm) after " + n(d.seconds) + " s";
}
std::string say(const domain::CommandEvent& d) { return d.text.find(' ') == std::string::npos ? "'" + d.text + "' sent to the rig's thread" : d.text; }

void flatten(const json& v, const std::string& key, std::string& out) {
  if (v.is_object() && !v.empty()) {
    for (const auto& [k, x] : v.items()) flatten(x, key.empty() ? k : key + "." + k, out);
    return;
  }
  std::string s;
  if (v.is_string())
    s = v.get<std::string>();
  else if (v.is_number())
    s = g(v.get<double>());
  else if (v.is_array()) {
    std::size_t k = 0;
    for (const json& x : v) {
      if (k == 8) {
        s += ", … (" + std::to_string(v.size()) + " values)";
        break;
      }
      s += (k++ ? ", " : "") + (x.is_number() ? g(x.get<double>()) : x.is_string() ? x.get<std::string>() : x.dump());
    }
    s = "[" + s + "]";
  } else {
    s = v.dump();  // true, false, null, {}
  }
  out += (out.empty() ? "" : ", ") + key + "=" + s;
}
}  // namespace event_words

using event_words::json;

std::string detail_pairs(const std::string& detail) {
  const json d = json::parse(detail, nullptr, false);
  if (d.is_discarded() || !d.is_object()) return detail;
  std::string out;
  event_words::flatten(d, "", out);
  return out;
}

std::string event_sentence(const db::EventRow& e) {
  if (e.kind == "state")
    return (e.from_state.empty() ? "" : e.from_state + " -> ") + (e.to_state.empty() ? "?" : e.to_state) + (e.detail.empty() ? "" : ": " + e.detail);
  std::string error;
  const auto ev = domain::decode_event(e.kind, e.detail, error);
  if (!ev) return detail_pairs(e.detail);  // a kind this version does not know, or a detail of another shape: its pairs
  return std::visit([](const auto& d) { return event_words::say(d); }, *ev);
}

std::string event_line(const db::EventRow& e, std::size_t kind_width) {
  const bool iso = e.at.size() >= 19 && e.at[10] == 'T';
  const std::string pad(kind_width > e.kind.size() ? kind_width - e.kind.size() : 0, ' ');
  return (iso ? e.at.substr(11, 8) + " UTC" : e.at) + "  " + e.kind + pad + "  " + event_sentence(e);
}

}  // namespace hystlab::cli
