#include "report_html.hpp"

#include <cmath>
#include <map>
#include <numbers>
#include <sstream>

#include "report_svg.hpp"

namespace hystlab::web::report {
using nlohmann::json;

namespace {

double d(const json& j, const char* key, double fallback = NAN) {
  return j.is_object() && j.contains(key) && j[key].is_number() ? j[key].get<double>() : fallback;
}
std::string s(const json& j, const char* key) { return j.is_object() && j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : ""; }
std::string unit(double v, const char* u, int digits = 3) { return std::isfinite(v) ? num(v, digits) + " " + u : "–"; }

const char* kStyle = R"(
body { font: 10.5pt/1.4 "DejaVu Sans", sans-serif; color: #111; max-width: 60em; margin: 1.5em auto; padding: 0 1em; }
h1 { font-size: 17pt; margin: 0 0 .2em; } h2 { font-size: 13pt; margin: 1.4em 0 .4em; border-bottom: 1px solid #999; }
h3 { font-size: 11pt; margin: 1em 0 .3em; } h2, h3 { page-break-after: avoid; } code { font-size: 9pt; overflow-wrap: anywhere; } .muted { color: #555; } .bad { color: #b71c1c; }
table { border-collapse: collapse; margin: .3em 0; } td, th { padding: .15em .6em; border-bottom: 1px solid #ddd; text-align: left; vertical-align: top; }
td.n, th.n { text-align: right; font-variant-numeric: tabular-nums; } .state { font-weight: bold; padding: 0 .3em; border: 1px solid #999; }
pre { font-size: 9pt; background: #f4f4f4; padding: .5em; white-space: pre-wrap; } figure { margin: .5em 0; page-break-inside: avoid; }
figcaption { font-size: 9.5pt; color: #333; } section { page-break-inside: auto; } tr { page-break-inside: avoid; }
@page { size: A4; margin: 15mm 12mm; }
)";

void kv(std::ostringstream& o, const std::string& k, const std::string& v) { o << "<tr><th>" << esc(k) << "</th><td>" << v << "</td></tr>"; }

void header(std::ostringstream& o, const json& doc) {
  const json& c = doc["campaign"];
  o << "<h1>Campaign #" << c.value("id", 0) << ": "
    << esc(s(c, "kind") == "sine"  ? "sine sweep"
           : s(c, "kind") == "fot" ? "FOT identification"
                                   : s(c, "kind"))
    << " on " << esc(s(c, "rig")) << "</h1>";
  o << "<p><span class=\"state\">" << esc(s(c, "state")) << "</span> " << esc(s(c, "reason")) << "</p><table>";
  kv(o, "created", esc(s(c, "created_at")) + " (UTC)");
  kv(o, "last change", esc(s(c, "updated_at")) + " (UTC)");
  // The record as it stands (at submission, or changed since: db/campaign_record.hpp).
  if (!s(c, "specimen").empty()) kv(o, "specimen", esc(s(c, "specimen")));
  if (!s(c, "notes").empty()) kv(o, "notes", "<span style=\"white-space: pre-wrap\">" + esc(s(c, "notes")) + "</span>");
  if (!s(c, "record_changed_at").empty()) kv(o, "record changed", esc(s(c, "record_changed_at")) + " (UTC)");
  kv(o, "report", "generated " + esc(s(doc, "generated_at")) + " (UTC) by " + esc(s(doc, "software")) + " from the stored records only");
  o << "</table>";
}

void rig_section(std::ostringstream& o, const json& doc) {
  const json& r = doc["rig"];
  o << "<section><h2>Rig and plan</h2><table>";
  kv(o, "rig",
     esc(s(doc["campaign"], "rig")) +
         (r.is_object() ? " · " + esc(s(r, "kind") == "shaker" ? "shaker" : "load frame") + " · " + esc(s(r, "description")) : ""));
  if (r.is_object() && r["envelope"].is_object()) {
    std::string env;
    for (const auto& [k, v] : r["envelope"].items())
      env += (env.empty() ? "" : " · ") + esc(k) + " " + esc(v.is_number_float() ? num(v.get<double>()) : v.dump());
    kv(o, "envelope", env);
  }
  if (r.is_object() && r["supervision"].is_object()) {
    std::string sup;
    for (const auto& [k, v] : r["supervision"].items())
      sup += (sup.empty() ? "" : " · ") + esc(k) + " " + esc(v.is_number_float() ? num(v.get<double>()) : v.dump());
    kv(o, "supervision", sup);
  }
  o << "</table><h3>The plan, as submitted</h3><table>";
  const json plan = doc["campaign"].value("plan", json::object());  // a copy: iterating a temporary's items() would dangle
  for (const auto& [k, v] : plan.items()) kv(o, k, "<code>" + esc(v.dump()) + "</code>");
  o << "</table></section>";
}

void quality_section(std::ostringstream& o, const json& runs) {
  o << "<section><h2>Data quality, per run</h2><table><tr><th>run</th><th>role</th><th class=n>samples</th><th class=n>rate (rig time)</th>"
       "<th class=n>missed deadlines</th><th class=n>holes</th><th class=n>I/O errors</th><th>warnings</th></tr>";
  for (const json& r : runs) {
    const json& q = r.value("quality", json());
    o << "<tr><td>#" << r.value("id", 0) << "</td><td>" << esc(s(r, "role")) << "</td><td class=n>" << r.value("samples", 0) << "</td>";
    if (!q.is_object()) {
      o << "<td colspan=5 class=muted>no quality figures stored for this run</td></tr>";
      continue;
    }
    const double scale = d(q, "time_scale", 1);
    o << "<td class=n>" << unit(d(q, "rate_hz"), "Hz", 4) << (scale > 1 ? " <span class=muted>(simulated " + num(scale) + "× real time)</span>" : "")
      << "</td><td class=n>" << q.value("missed_deadlines", 0) << "</td><td class=n>" << q.value("gaps", 0) << "</td><td class=n>" << q.value("io_errors", 0)
      << "</td><td>";
    for (const json& w : q.value("warnings", json::array())) o << "<div class=bad>" << esc(w.is_string() ? w.get<std::string>() : w.dump()) << "</div>";
    o << "</td></tr>";
  }
  o << "</table></section>";
}

// The campaign's loop with the recommended table's force over it.
void loop_figure(std::ostringstream& o, const json& loop) {
  if (!loop.is_object() || !loop["x"].is_array()) return;
  Series measured{loop["x"].get<std::vector<double>>(), loop["y"].get<std::vector<double>>(), "measured", "#1565c0"};
  std::vector<Series> series{measured};
  if (loop["model"].is_object())
    series.push_back(
        {measured.x, loop["model"]["force_N"].get<std::vector<double>>(), "table #" + std::to_string(loop["model"].value("table", 0)), "#e65100", true});
  o << "<figure>" << svg_xy(series, {"displacement (mm)"}, {"force (N)"}) << "<figcaption>Run #" << loop.value("run", 0) << ": " << loop.value("samples", 0)
    << " samples, " << loop.value("reversals", 0) << " reversals, drawn with " << loop.value("points", 0) << " points (every reversal kept)"
    << (loop["model"].is_object() ? "; dashed: the identified table's force on the same input" : "") << ".</figcaption></figure>";
}

void everett_figure(std::ostringstream& o, const json& nodes) {
  if (!nodes.is_object() || !nodes.contains("grid")) return;
  std::vector<HeatCell> cells;
  for (const json& n : nodes["nodes"]) cells.push_back({d(n, "alpha"), d(n, "beta"), d(n, "F")});
  const json& g = nodes["grid"];
  o << "<figure>" << svg_heatmap(cells, d(g, "lo_mm"), d(g, "hi_mm"), g.value("n", 0)) << "<figcaption>The Everett table measured by the FOT input: F(α, β) = "
    << "f(α) − f(α, β) at each of " << nodes.value("identified", 0) << " of " << nodes.value("required", 0) << " nodes (n = " << g.value("n", 0)
    << "); the colour scale spans the measured F.</figcaption></figure>";
}

// A table's provenance in a line: its scalar fields ("prior: signed · lambda: 0.01 · folds: 5").
std::string provenance_text(const json& p) {
  if (!p.is_object()) return "";
  std::string out;
  for (const auto& [k, v] : p.items()) {
    if (v.is_object() || v.is_array() || v.is_null()) continue;
    const std::string text = v.is_string() ? v.get<std::string>() : v.is_number_float() ? num(v.get<double>()) : v.dump();
    out += (out.empty() ? "" : " · ") + esc(k) + ": " + esc(text);
  }
  return out.empty() ? "" : "<br><span class=muted>" + out + "</span>";
}

void tables_section(std::ostringstream& o, const json& c, const json& provenance) {
  o << "<h3>Tables, scored on the held-out validation run</h3><table><tr><th>table</th><th>method</th><th class=n>n</th><th class=n>held-out RMS</th>"
       "<th class=n>held-out max</th><th class=n>fit RMS</th><th>provenance</th></tr>";
  for (const json& t : c.value("tables", json::array())) {
    const json& a = t.value("accuracy", json::object());
    const json& h = a.is_object() ? a.value("held_out", json::object()) : json::object();
    const json& ho = h.is_object() ? h.value("overall", json::object()) : json::object();
    const bool rec = a.is_object() && a.value("recommended", false);
    o << "<tr><td>#" << t.value("id", 0) << (rec ? " <b>(recommended)</b>" : "") << "</td><td>" << esc(s(t, "method")) << "</td><td class=n>" << t.value("n", 0)
      << "</td><td class=n>" << unit(d(ho, "rms_N"), "N") << "</td><td class=n>" << unit(d(ho, "max_N"), "N") << "</td><td class=n>"
      << unit(d(a.is_object() ? a.value("overall", json::object()) : json::object(), "rms_N"), "N") << "</td><td>"
      << (t.contains("run") && t["run"].is_number() ? "run #" + t["run"].dump() + ", " : "") << esc(s(t, "created_at"))
      << provenance_text(provenance.value(std::to_string(t.value("id", 0)), json())) << "</td></tr>";
  }
  o << "</table>";
  const json& r = c.value("recommendation", json());
  if (r.is_object()) o << "<p><b>Recommended: table #" << r.value("table", 0) << "</b>: " << esc(s(r, "why")) << ".</p>";
}

void shakedown_figure(std::ostringstream& o, const json& c) {
  const json& cycles = c.value("shakedown", json::array());
  if (!cycles.is_array() || cycles.empty()) return;
  if (cycles.size() < 2) {  // one point is no curve
    o << "<h3>Training (shakedown)</h3><p>" << cycles.size() << " cycle: peak force " << unit(d(cycles[0], "peak_force_N"), "N") << ", dissipated energy "
      << unit(d(cycles[0], "energy_Nmm"), "N·mm") << ". " << esc(s(c.value("training", json::object()), "why")) << ".</p>";
    return;
  }
  Series energy{{}, {}, "dissipated energy (N·mm)", "#6a1b9a", false, true}, peak{{}, {}, "peak force (N)", "#2e7d32", true, true};
  for (const json& k : cycles)
    energy.x.push_back(d(k, "cycle")), energy.y.push_back(d(k, "energy_Nmm")), peak.x.push_back(d(k, "cycle")), peak.y.push_back(d(k, "peak_force_N"));
  o << "<h3>Training (shakedown)</h3><figure>" << svg_xy({energy, peak}, {"training cycle"}, {"N·mm, N"}, 640, 260) << "<figcaption>"
    << esc(s(c.value("training", json::object()), "why")) << ".</figcaption></figure>";
}

// Per closed cycle: the figures a superelastic test standard (ASTM F2516) reports, in force and
// displacement units for springs: the plateau forces (the knees of each branch), the force at
// return, the residual displacement (unloaded to 1 % of the cycle's force range), the dissipated energy.
void cycles_table(std::ostringstream& o, const json& loops) {
  if (!loops.is_array() || loops.empty()) return;
  o << "<h3>Loop figures, per closed cycle</h3><table><tr><th>cycle</th><th>phase</th><th class=n>range</th><th class=n>peak force</th>"
       "<th class=n>loading plateau</th><th class=n>unloading plateau</th><th class=n>force at return</th><th class=n>residual displacement</th><th "
       "class=n>dissipated energy</th><th class=n>damping ratio</th></tr>";
  auto plateau = [](const json& k) {
    if (!k.is_object() || !k.value("plateau", false)) return std::string("<span class=muted>none</span>");
    return num(d(k, "lower_N")) + "–" + num(d(k, "upper_N")) + " N";
  };
  for (const json& l : loops)
    o << "<tr><td>" << l.value("k", 0) << " (run #" << l.value("run", 0) << ")</td><td>" << esc(s(l, "phase")) << "</td><td class=n>" << num(d(l, "min_mm"))
      << "–" << unit(d(l, "max_mm"), "mm") << "</td><td class=n>" << unit(d(l, "peak_force_N"), "N") << "</td><td class=n>"
      << plateau(l.value("loading_knees", json())) << "</td><td class=n>" << plateau(l.value("unloading_knees", json())) << "</td><td class=n>"
      << unit(d(l, "return_N"), "N") << "</td><td class=n>" << unit(d(l, "residual_mm"), "mm") << "</td><td class=n>" << unit(d(l, "energy_Nmm"), "N·mm")
      << "</td><td class=n>" << num(d(l, "damping_ratio")) << "</td></tr>";
  o << "</table>";
}

void fot_section(std::ostringstream& o, const json& doc) {
  const json& c = doc["campaign"];
  o << "<section><h2>Identification</h2>";
  loop_figure(o, doc.value("loop", json()));
  everett_figure(o, doc.value("nodes", json()));
  tables_section(o, c, doc.value("provenance", json::object()));
  shakedown_figure(o, c);
  cycles_table(o, doc.value("loops", json()));
  o << "</section>";
}

void sine_section(std::ostringstream& o, const json& sweep) {
  o << "<section><h2>Transmissibility</h2>";
  if (!sweep.is_object() || sweep["points"].empty()) {
    o << "<p class=muted>No point was measured.</p></section>";
    return;
  }
  const char* colors[] = {"#1565c0", "#c62828", "#2e7d32", "#6a1b9a", "#ef6c00", "#00838f"};
  std::map<std::string, Series> ratio, phase, predicted;
  for (const json& p : sweep["points"]) {
    const std::string key = num(d(p, "amplitude_mm")) + " mm " + s(p, "direction");
    const std::size_t k = ratio.count(key) ? 0 : ratio.size();
    if (!ratio.count(key)) {
      ratio[key] = {{}, {}, key, colors[k % 6]}, phase[key] = {{}, {}, key, colors[k % 6]};
      predicted[key] = {{}, {}, key + " (predicted)", colors[k % 6], true};
    }
    ratio[key].x.push_back(d(p, "frequency_hz")), ratio[key].y.push_back(d(p, "ratio"));
    phase[key].x.push_back(d(p, "frequency_hz")), phase[key].y.push_back(d(p, "phase_rad") * 180 / std::numbers::pi);
    if (std::isfinite(d(p, "predicted_ratio"))) predicted[key].x.push_back(d(p, "frequency_hz")), predicted[key].y.push_back(d(p, "predicted_ratio"));
  }
  std::vector<Series> r, ph;
  for (auto& [k, v] : ratio) r.push_back(v);
  for (auto& [k, v] : predicted)
    if (!v.x.empty()) r.push_back(v);
  for (auto& [k, v] : phase) ph.push_back(v);
  o << "<figure>" << svg_xy(r, {"frequency (Hz)", true}, {"transmissibility |X/Y|", true}) << "<figcaption>Mass against base amplitude, per amplitude and "
    << "direction; dashed: the isolator model's prediction.</figcaption></figure>";
  o << "<figure>" << svg_xy(ph, {"frequency (Hz)", true}, {"phase (°)"}, 640, 260) << "<figcaption>Phase of the mass against the base.</figcaption></figure>";
  o << "<h3>Resonances</h3><table><tr><th>amplitude, direction</th><th class=n>frequency</th><th class=n>peak</th><th class=n>half-power band</th><th "
       "class=n>Q</th></tr>";
  for (const json& cv : sweep["measured"]["curves"]) {
    const json& res = cv["resonance"];
    o << "<tr><td>" << num(d(cv, "amplitude_mm")) << " mm " << esc(s(cv, "direction")) << "</td>";
    if (!res.is_object())
      o << "<td colspan=4 class=muted>not within the swept band</td></tr>";
    else
      o << "<td class=n>" << unit(d(res, "frequency_hz"), "Hz") << (res.value("at_edge", false) ? " (at the band's edge)" : "") << "</td><td class=n>"
        << num(d(res, "peak_ratio")) << "</td><td class=n>" << unit(d(res, "bandwidth_hz"), "Hz") << "</td><td class=n>" << num(d(res, "q")) << "</td></tr>";
  }
  o << "</table><h3>Jumps (up against down)</h3>";
  if (sweep["measured"].value("compared", 0) == 0)
    o << "<p>No amplitude was swept both ways: nothing to compare.</p>";
  else if (sweep["measured"]["jumps"].empty())
    o << "<p>No jump beyond " << num(d(sweep, "jump_threshold") * 100) << " % between the directions.</p>";
  else {
    o << "<table><tr><th>amplitude</th><th class=n>between</th><th class=n>largest difference</th></tr>";
    for (const json& j : sweep["measured"]["jumps"])
      o << "<tr><td>" << unit(d(j, "amplitude_mm"), "mm") << "</td><td class=n>" << num(d(j, "lo_hz")) << "–" << unit(d(j, "hi_hz"), "Hz")
        << "</td><td class=n>" << num(d(j, "max_difference") * 100) << " %</td></tr>";
    o << "</table>";
  }
  o << "</section>";
}

void events_section(std::ostringstream& o, const json& events) {
  o << "<section><h2>Record</h2><table><tr><th>at (UTC)</th><th>what</th></tr>";
  for (const json& e : events) {
    if (s(e, "kind") != "state") continue;
    const json& det = e.value("detail", json());
    o << "<tr><td>" << esc(s(e, "at")) << "</td><td>" << esc(s(e, "from")) << " → <b>" << esc(s(e, "to")) << "</b>"
      << (det.is_string() && !det.get<std::string>().empty() ? ": " + esc(det.get<std::string>()) : "") << "</td></tr>";
  }
  o << "</table></section>";
}

}  // namespace

std::string render_html(const json& doc) {
  std::ostringstream o;
  const json& c = doc["campaign"];
  o << "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>hystlab campaign #" << c.value("id", 0) << " report</title><style>" << kStyle
    << "</style></head><body>";
  header(o, doc);
  rig_section(o, doc);
  quality_section(o, c.value("runs", json::array()));
  if (s(c, "kind") == "sine")
    sine_section(o, doc.value("sweep", json()));
  else
    fot_section(o, doc);
  events_section(o, doc.value("events", json::array()));
  o << "</body></html>\n";
  return o.str();
}

}  // namespace hystlab::web::report
