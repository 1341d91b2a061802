#include "event_text.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <functional>
#include <map>

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

double value(const json& d, const char* key) {
  const auto it = d.find(key);
  return it != d.end() && it->is_number() ? it->get<double>() : 0.0;
}

std::string text(const json& d, const char* key) {
  const auto it = d.find(key);
  return it == d.end() ? "" : it->is_string() ? it->get<std::string>() : it->dump();
}

// "1 sample", "3 samples"
std::string count(double n, const std::string& one, const std::string& many = "") { return g(n) + " " + (n == 1 ? one : many.empty() ? one + "s" : many); }

std::string range(const json& d, const char* key, const char* unit) {
  const auto it = d.find(key);
  if (it == d.end() || !it->is_array() || it->size() != 2 || !(*it)[0].is_number() || !(*it)[1].is_number()) return "?";
  return g((*it)[0].get<double>()) + ".." + g((*it)[1].get<double>()) + " " + unit;
}

std::string signed_pct(const json& d, const char* key) {
  const auto it = d.find(key);
  if (it == d.end() || !it->is_number()) return "";
  const double v = it->get<double>();
  return std::string(" (") + (v > 0 ? "+" : "") + g(v) + " %)";
}

std::string limits(const json& d) {
  return "displacement " + range(d, "displacement_mm", "mm") + ", force up to " + num(d, "force_N") + " N, rate up to " + num(d, "rate_mm_s") +
         " mm/s; safe position " + num(d, "safe_position_mm") + " mm at " + num(d, "safe_rate_mm_s") + " mm/s; in position within " + num(d, "in_position_mm") +
         " mm";
}

std::string envelope(const json& d) {
  if (d.contains("stroke_mm"))
    return "the rig's envelope: stroke " + range(d, "stroke_mm", "mm") + ", force " + num(d, "force_N") + " N, speed " + num(d, "speed_mm_s") +
           " mm/s, acceleration " + num(d, "accel_mm_s2") + " mm/s²";
  return "the rig's envelope: base displacement " + num(d, "displacement_mm") + " mm, velocity " + num(d, "velocity_mm_s") + " mm/s, acceleration " +
         num(d, "accel_g") + " g, " + range(d, "frequency_hz", "Hz");
}

std::string fit(const json& d) {
  const json overall = d.contains("accuracy") ? d["accuracy"].value("overall", json::object()) : json::object();
  return "partial table (" + num(d, "nodes") + " of " + num(d, "required") + " nodes): RMS " + num(overall, "rms_N") + " N, max " + num(overall, "max_N") +
         " N on the run so far";
}

std::string quality(const json& d) {
  std::string s = "run " + num(d, "run") + ": " + count(value(d, "samples"), "sample") + " in " + num(d, "rig_seconds") + " s of rig time (" +
                  num(d, "rate_hz") + " Hz; " + num(d, "expected_rate_hz") + " Hz expected)";
  std::string issues;
  const auto add = [&issues](const std::string& what) { issues += (issues.empty() ? "" : ", ") + what; };
  if (value(d, "gaps") == 1)
    add("1 gap of " + g(1e3 * value(d, "gap_total_s")) + " ms");
  else if (value(d, "gaps") > 1)
    add(count(value(d, "gaps"), "gap") + " (" + g(1e3 * value(d, "gap_total_s")) + " ms in all, the longest " + g(1e3 * value(d, "longest_gap_s")) + " ms)");
  struct Counted {
    const char *key, *one, *many;
  };
  static const Counted counted[] = {
      {"lost_samples", "sample lost", "samples lost"},   {"missed_deadlines", "missed deadline", "missed deadlines"},
      {"late_wakeups", "late wake-up", "late wake-ups"}, {"dropped", "sample dropped by the writer", "samples dropped by the writer"},
      {"io_errors", "I/O error", "I/O errors"},          {"timeouts", "timeout", "timeouts"},
      {"reconnects", "reconnection", "reconnections"}};
  for (const Counted& c : counted)
    if (value(d, c.key) > 0) add(count(value(d, c.key), c.one, c.many));
  return s + (issues.empty() ? ", nothing lost" : ": " + issues);
}

std::string shakedown(const json& d) {
  return "cycle " + num(d, "cycle") + ": peak force " + num(d, "peak_force_N") + " N" + signed_pct(d, "peak_change_pct") + ", energy " + num(d, "energy_Nmm") +
         " N·mm" + signed_pct(d, "energy_change_pct") + ", damping ratio " + num(d, "damping_ratio") + (d.value("stable", false) ? ", stable" : "");
}

std::string retake(const json& d) {
  if (d.contains("frequency_hz")) return "at " + num(d, "frequency_hz") + " Hz, attempt " + num(d, "attempt") + ": " + text(d, "why");
  std::string rows;
  for (const json& r : d.value("rows", json::array())) rows += (rows.empty() ? "" : ", ") + r.dump();
  return "row(s) " + rows + " again (round " + num(d, "round") + "): " + text(d, "why");
}

std::string sine_step(const json& d) {
  return "step " + num(d, "k") + " of " + num(d, "of") + " (pass " + num(d, "pass") + " of " + num(d, "passes") + "): " + num(d, "frequency_hz") + " Hz, " +
         num(d, "amplitude_mm") + " mm " + text(d, "direction") + ", drive " + num(d, "drive_mm") + " mm; about " + num(d, "eta_s") + " s left";
}

std::string transmissibility(const json& d) {
  return "point " + num(d, "k") + " of " + num(d, "of") + ": " + num(d, "frequency_hz") + " Hz, " + num(d, "amplitude_mm") + " mm " + text(d, "direction") +
         ": ratio " + num(d, "ratio") + ", phase " + num(d, "phase_rad") + " rad, control error " + num(d, "control_error_pct") + " %";
}

std::string sweep_done(const json& d) {
  std::string s = num(d, "points") + " of " + num(d, "of") + " points in " + num(d, "seconds") + " s (" + num(d, "nominal_seconds") + " s planned)";
  if (value(d, "warnings") > 0) s += ", " + count(value(d, "warnings"), "control warning");
  if (const std::string p = text(d, "predicted_with"); !p.empty()) s += "; predicted with " + p;
  return s;
}

std::string control(const json& d, const std::string& kind) {
  const std::string at = "at " + num(d, "frequency_hz") + " Hz: ";
  if (kind == "control_unreached")
    return at + "the demand " + num(d, "demand_mm") + " mm not reached in " + count(value(d, "windows"), "window") + " (error " + num(d, "error_pct") +
           " %, drive " + num(d, "drive_mm") + " mm" + (d.value("limited", false) ? ", at its limit" : "") + ")" +
           (d.contains("while") ? "; measured anyway" : "");
  const std::string base = at + "base " + num(d, "base_mm") + " mm for a demand of " + num(d, "demand_mm") + " mm (error " + num(d, "error_pct") + " %";
  if (kind == "control_abort") return base + "): stopped, drive " + num(d, "drive_mm") + " mm";
  return base + ", " + text(d, "band") + ")";
}

// The specimen and notes as changed (db/campaign_record.hpp): the notes on one line.
std::string record(const json& d) {
  std::string notes = text(d, "notes");
  for (char& c : notes) c = c == '\n' ? ' ' : c;
  const std::string specimen = text(d, "specimen");
  return "the record changed: specimen " + (specimen.empty() ? "(none)" : specimen) + "; notes " + (notes.empty() ? "(none)" : notes);
}

using Sentence = std::function<std::string(const json&)>;

const std::map<std::string, Sentence>& sentences() {
  static const std::map<std::string, Sentence> m{
      {"limits", limits},
      {"record", record},
      {"envelope", envelope},
      {"fit", fit},
      {"quality", quality},
      {"validation",
       [](const json& d) {
         return "run " + num(d, "run") + ": " + num(d, "reversals") + " reversals from seed " + num(d, "seed") + " (" + text(d, "why") + ")";
       }},
      {"recommendation", [](const json& d) { return "table " + num(d, "table") + " (" + text(d, "method") + ", n = " + num(d, "n") + "): " + text(d, "why"); }},
      {"training",
       [](const json& d) { return count(value(d, "cycles"), "cycle") + (d.value("stable", false) ? ", stable: " : ", not stable: ") + text(d, "why"); }},
      {"shakedown", shakedown},
      {"retake", retake},
      {"gap",
       [](const json& d) { return "no samples from " + num(d, "from_s") + " s to " + num(d, "to_s") + " s of rig time (" + num(d, "length_ms") + " ms)"; }},
      {"gaps",
       [](const json& d) {
         return count(value(d, "count"), "gap") + " in the data, " + num(d, "total_ms") + " ms in all, the longest " + num(d, "longest_ms") + " ms";
       }},
      {"safe",
       [](const json& d) {
         return "at the safe position: " + num(d, "position_mm") + " mm (target " + num(d, "target_mm") + " mm) after " + num(d, "seconds") + " s";
       }},
      {"sine_step", sine_step},
      {"transmissibility", transmissibility},
      {"sweep_done", sweep_done},
      {"control_abort", [](const json& d) { return control(d, "control_abort"); }},
      {"control_warning", [](const json& d) { return control(d, "control_warning"); }},
      {"control_unreached", [](const json& d) { return control(d, "control_unreached"); }},
      {"unsettled",
       [](const json& d) {
         return "at " + num(d, "frequency_hz") + " Hz: not settled after " + num(d, "cycles") + " cycles (still changing " + num(d, "change_pct") + " %)";
       }},
  };
  return m;
}

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
  if (e.kind == "command") return e.detail.find(' ') == std::string::npos ? "'" + e.detail + "' sent to the rig's thread" : e.detail;
  const auto& known = event_words::sentences();
  const auto it = known.find(e.kind);
  const json d = json::parse(e.detail.empty() ? "{}" : e.detail, nullptr, false);
  if (it == known.end() || !d.is_object()) return detail_pairs(e.detail);
  try {
    return it->second(d);
  } catch (const json::exception&) {  // a detail of another shape (an older hystlabd): its pairs
    return detail_pairs(e.detail);
  }
}

std::string event_line(const db::EventRow& e, std::size_t kind_width) {
  const bool iso = e.at.size() >= 19 && e.at[10] == 'T';
  const std::string pad(kind_width > e.kind.size() ? kind_width - e.kind.size() : 0, ' ');
  return (iso ? e.at.substr(11, 8) + " UTC" : e.at) + "  " + e.kind + pad + "  " + event_sentence(e);
}

}  // namespace hystlab::cli
