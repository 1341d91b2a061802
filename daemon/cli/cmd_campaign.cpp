// hystlab campaign / tables (runs: cmd_runs.cpp). Submitting and commanding a campaign go to the running
// hystlabd over its HTTP API (daemon_client.hpp); its records are read from the database file.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "daemon_client.hpp"
#include "event_text.hpp"
#include "hystlab/db/campaign_record.hpp"
#include "hystlab/db/store.hpp"
#include "hystlab/domain/plan.hpp"
#include "hystlab/domain/signals.hpp"
#include "hystlab/fmu/element_export.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/sweep_analysis.hpp"
#include "hystlab/models/table_export.hpp"

namespace hystlab::cli {
namespace {
const char* kCampaignHelp = R"(usage: hystlab campaign submit --plan P.json [--rig NAME] [--daemon URL] [--token T]
       hystlab campaign preview --plan P.json [--rig NAME] [--daemon URL] [--token T]
       hystlab campaign pause|resume|abort|estop ID [--daemon URL] [--token T]
       hystlab campaign record ID [--specimen TEXT] [--notes TEXT | --notes-file F] [--daemon URL] [--token T]
       hystlab campaign list [--db hystlab.db]
       hystlab campaign show ID [--json] [--db hystlab.db]

Campaigns run on hystlabd's rigs one after another. submit, preview and the commands go to the
running daemon over its HTTP API: --daemon (or $HYSTLAB_DAEMON, default http://127.0.0.1:8080),
with the daemon's token when it has one ($HYSTLAB_TOKEN, or --token, which others see in ps). submit validates the plan
(an error names the field) and queues it; preview says what it would do (duration, samples, peak
speed and force) without queueing it; pause holds the rig; resume continues (after a long pause,
or for an interrupted or held campaign, with a wipe-out preamble and the rows not yet measured);
abort drives to the safe position; estop triggers the rig's e-stop at once (no motion). record
changes what the lab records with a campaign, in any state: its specimen (one line, at most 200
characters) and notes (at most 4000), set at submission by the plan's "specimen" and "notes";
each change is kept in its events. The rig
defaults to the only one the daemon has. A waveform plan may give "points_csv": a CSV file
(beside the plan) whose displacement_mm column is the input, e.g. a random validation path.
list and show read the daemon's database file, with or without a daemon running.
)";
const char* kTablesHelp = R"(usage: hystlab tables list [--db hystlab.db]
       hystlab tables export ID [--format json|csv|m|h|fmu] [-o FILE] [--db hystlab.db]

list: every table hystlabd identified, one a row: its campaign, method, n and range; its error
on its own samples (RMS and max in N, RMS in % of the force range) and held out, on its
campaign's validation run, which no table was built from; * marks the table its campaign
recommends, - a figure there is none of. export writes one (docs/FORMATS.md): json (the stored
document as it is), csv, m (MATLAB/Octave), h (C header) or fmu (FMI 2.0, needs -o FILE.fmu).
--db must name hystlabd's database (it is never created here).
)";

std::int64_t id_arg(const Args& args, std::size_t k, const char* what) {
  if (args.size() <= k) throw CliError(std::string("missing ") + what);
  try {
    std::size_t used = 0;
    const long long v = std::stoll(args[k], &used);
    if (used == args[k].size() && v > 0) return v;
  } catch (...) {
  }
  throw CliError(std::string(what) + " must be a positive whole number, got '" + args[k] + "'");
}

Args rest(const Args& args, std::size_t from) { return Args(args.begin() + static_cast<std::ptrdiff_t>(std::min(from, args.size())), args.end()); }

// A waveform's points_csv: a file beside the plan, by name only (no other folder, no device).
std::filesystem::path points_file(const std::string& plan_path, const nlohmann::json& name) {
  if (!name.is_string() || name.get<std::string>().empty()) throw CliError(plan_path + ": points_csv must be a file name");
  const std::filesystem::path file = name.get<std::string>();
  if (file.has_parent_path() || file.is_absolute() || file == "." || file == "..")
    throw CliError(plan_path + ": points_csv '" + file.string() + "' must be a file beside the plan (a name, no folder)");
  const std::filesystem::path full = std::filesystem::path(plan_path).parent_path() / file;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(full, ec)) throw CliError(plan_path + ": points_csv '" + full.string() + "' is not a file");
  if (std::filesystem::file_size(full, ec) > (64U << 20)) throw CliError(plan_path + ": points_csv '" + full.string() + "' is over 64 MiB");
  return full;
}

// The plan file as JSON, a waveform's points_csv read into points_mm (the daemon has no access to
// the user's files); the daemon checks the plan itself and names the field that is wrong.
nlohmann::json load_plan(const std::string& path) {
  nlohmann::json j = read_json_file(path, "plan file").json;
  if (j.is_object() && j.contains("points_csv")) {
    j["points_mm"] = Csv::load(points_file(path, j["points_csv"]).string()).column("displacement_mm");
    j.erase("points_csv");
  }
  return j;
}

std::string round_g(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

// A table's scores as stored (table_score.hpp's accuracy_json): on its own samples, and held out
// (on its campaign's validation run, which no table was built from). Empty: not scored.
struct Scores {
  std::string rms, rms_pct, max, held_rms, held_max;
  bool recommended = false;
};

Scores scores_of(const std::string& json_text) {
  Scores s;
  const auto a = nlohmann::json::parse(json_text, nullptr, false);
  if (a.is_discarded() || !a.is_object()) return s;
  if (a.contains("overall") && a["overall"].is_object()) {
    const auto& o = a["overall"];
    s.rms = round_g(o.value("rms_N", 0.0)), s.rms_pct = round_g(100 * o.value("rms_norm", 0.0)), s.max = round_g(o.value("max_N", 0.0));
  }
  if (a.contains("held_out") && a["held_out"].is_object() && a["held_out"].contains("overall")) {
    const auto& o = a["held_out"]["overall"];
    s.held_rms = round_g(o.value("rms_N", 0.0)), s.held_max = round_g(o.value("max_N", 0.0));
  }
  s.recommended = a.value("recommended", false);
  return s;
}

// One line of a table's accuracy on its own samples: "RMS 3.2 N (0.4 % of range), max 12 N", or "".
std::string accuracy_line(const std::string& json_text) {
  const Scores s = scores_of(json_text);
  return s.rms.empty() ? "" : "RMS " + s.rms + " N (" + s.rms_pct + " % of range), max " + s.max + " N";
}

// The held-out figures (on the validation run): "RMS 1.1 N, max 4 N (recommended)", or "".
std::string heldout_line(const std::string& json_text) {
  const Scores s = scores_of(json_text);
  return s.held_rms.empty() ? "" : "RMS " + s.held_rms + " N, max " + s.held_max + " N" + (s.recommended ? " (recommended)" : "");
}

// hystlab tables list: one row a table, the columns aligned, and what its marks mean below it.
void list_tables(db::ReadSource& store) {
  const std::vector<Column> columns{{"id", true},
                                    {"campaign", true},
                                    {"method"},
                                    {"n", true},
                                    {"range (mm)"},
                                    {"RMS (N)", true},
                                    {"% range", true},
                                    {"max (N)", true},
                                    {"held-out RMS (N)", true},
                                    {"held-out max (N)", true},
                                    {""},
                                    {"created"}};
  std::vector<std::vector<std::string>> rows;
  bool star = false, dash = false;
  const auto or_dash = [&dash](const std::string& v) { return v.empty() ? (dash = true, std::string("-")) : v; };
  for (const auto& t : store.tables()) {
    const Scores s = scores_of(t.accuracy_json);
    star = star || s.recommended;
    rows.push_back({std::to_string(t.id), or_dash(t.campaign ? std::to_string(*t.campaign) : ""), t.method, std::to_string(t.n),
                    round_g(t.range_lo) + ".." + round_g(t.range_hi), or_dash(s.rms), or_dash(s.rms_pct), or_dash(s.max), or_dash(s.held_rms),
                    or_dash(s.held_max), s.recommended ? "*" : "", utc_time(t.created_at)});
  }
  std::cout << aligned_table(columns, rows);
  std::string legend;
  if (star) legend += "*: the table its campaign recommends (the lowest held-out error)";
  if (dash) legend += std::string(legend.empty() ? "" : "   ") + "-: none (no campaign, or not scored)";
  if (!legend.empty()) std::cout << legend << "\n";
}

int print_preview(const nlohmann::json& p) {
  std::cout << p.value("kind", "") << " on '" << p.value("rig", "") << "': " << round_g(p.value("duration_s", 0.0)) << " s, "
            << p.value("samples", std::int64_t{0}) << " samples at " << round_g(p.value("sample_rate_hz", 0.0)) << " Hz";
  if (p.value("nodes", 0) > 0) std::cout << ", " << p.value("nodes", 0) << (p.value("kind", "") == "sine" ? " steps" : " FOT nodes");
  if (const double scale = p.value("time_scale", 1.0); scale > 1)  // a simulator faster than real time
    std::cout << "\n  the simulator runs " << round_g(scale) << "x faster than real time: " << round_g(p.value("wall_s", 0.0)) << " s of wall time, "
              << p.value("stored_samples", std::int64_t{0}) << " samples stored (" << round_g(p.value("stored_rate_hz", 0.0)) << " Hz of rig time)";
  if (p.contains("design") && p["design"].is_object()) {
    const nlohmann::json& d = p["design"];
    std::cout << "\n  adaptive design: its rows take at most " << round_g(d.value("budget_s", 0.0)) << " s (the " << d.value("coarse_subdivisions", 0)
              << " coarse rows first, tops on " << d.value("finest_subdivisions", 0) << " subdivisions)";
    if (d.value("target_rms_N", 0.0) > 0) std::cout << ", until an estimated held-out RMS of " << round_g(d.value("target_rms_N", 0.0)) << " N";
  }
  std::cout << "\n  peak speed " << round_g(p.value("peak_speed_mm_s", 0.0)) << " mm/s";
  if (p.contains("peak_force_N") && p["peak_force_N"].is_number())
    std::cout << ", peak force " << round_g(p["peak_force_N"].get<double>()) << " N (limit " << round_g(p.value("force_limit_N", 0.0)) << " N; from "
              << p.value("force_source", "") << ")";
  if (p.contains("peak_accel_m_s2") && p["peak_accel_m_s2"].is_number())
    std::cout << ", peak acceleration " << round_g(p["peak_accel_m_s2"].get<double>()) << " m/s^2";
  std::cout << "\n";
  return 0;
}

// A sine campaign's points and its resonance table (measured, and predicted where it was).
void print_sweep(db::ReadSource& store, const db::CampaignRow& row) {
  const auto rows = store.transmissibility(row.id);
  if (rows.empty()) return;
  double threshold = 0.10, worst = 0;
  try {
    threshold = domain::parse_plan(nlohmann::json::parse(row.plan)).sine.jump_threshold_pct / 100;
  } catch (const std::exception&) {  // a plan of an older hystlab: the default threshold
  }
  std::vector<models::SweepCurvePoint> measured, predicted;
  for (const auto& t : rows) {
    const auto d = nlohmann::json::parse(t.detail.empty() ? "{}" : t.detail, nullptr, false);
    if (d.is_object()) worst = std::max(worst, std::fabs(d.value("control_error_pct", 0.0)));
    const double a = t.demand_mm > 0 ? t.demand_mm : t.base_amplitude_mm;
    const bool up = t.direction != "down";
    measured.push_back({a, up, {t.frequency_hz, t.ratio, t.phase_rad}});
    if (std::isfinite(t.predicted_ratio)) predicted.push_back({a, up, {t.frequency_hz, t.predicted_ratio, t.predicted_phase_rad}});
  }
  std::cout << "  sweep: " << rows.size() << " points, the worst control error " << round_g(worst) << " %\n";
  for (const auto& [what, pts] : {std::pair{"measured", &measured}, std::pair{"predicted", &predicted}}) {
    const models::SweepReport r = models::analyse_sweep(*pts, threshold);
    for (const auto& c : r.curves) {
      if (!c.resonance) continue;
      const auto& z = *c.resonance;
      std::cout << "    " << what << " " << round_g(c.amplitude_mm) << " mm " << (c.up ? "up" : "down") << ": resonance " << round_g(z.frequency_hz)
                << " Hz, peak " << round_g(z.peak_ratio);
      if (z.q > 0) std::cout << ", Q " << (z.resolved ? "" : ">= ") << round_g(z.q);
      if (std::isfinite(c.damping_at_resonance)) std::cout << ", equivalent damping " << round_g(c.damping_at_resonance);  // the backbone's
      std::cout << (z.at_edge ? " (at the sweep's edge)" : "") << "\n";
    }
    for (const auto& a : r.jumps)
      for (const auto& j : a.jumps)
        std::cout << "    " << what << " " << round_g(a.amplitude_mm) << " mm: up and down differ by up to " << round_g(100 * j.max_difference) << " % between "
                  << round_g(j.lo_hz) << " and " << round_g(j.hi_hz) << " Hz\n";
  }
}

void show_json(db::ReadSource& store, const db::CampaignRow& row) {
  const auto plan = nlohmann::json::parse(row.plan, nullptr, false);
  const std::string why = store.state_reason(row.id, row.state);
  nlohmann::json j{{"id", row.id},
                   {"kind", domain::to_string(row.kind)},
                   {"rig", store.rig_name(row.rig_id)},
                   {"state", domain::to_string(row.state)},
                   {"reason", why.empty() ? nlohmann::json() : nlohmann::json(why)},
                   {"created_at", row.created_at},
                   {"updated_at", row.updated_at},
                   {"plan", plan},
                   {"runs", nlohmann::json::array()},
                   {"tables", nlohmann::json::array()},
                   {"events", nlohmann::json::array()}};
  const db::CampaignRecord record = db::campaign_record(store, row);  // the plan's, or as changed since
  j["specimen"] = record.specimen.empty() ? nlohmann::json() : nlohmann::json(record.specimen);
  j["notes"] = record.notes.empty() ? nlohmann::json() : nlohmann::json(record.notes);
  for (const auto& r : store.runs(row.id))
    j["runs"].push_back({{"id", r.id}, {"role", r.role}, {"state", r.state}, {"samples", r.samples}, {"nodes", r.nodes}});
  j["loops"] = nlohmann::json::array();
  for (const auto& l : store.loops(row.id)) {
    auto fig = nlohmann::json::parse(l.figures_json, nullptr, false);
    if (!fig.is_object()) continue;
    fig["run"] = l.run, fig["phase"] = l.phase;
    j["loops"].push_back(std::move(fig));
  }
  for (const auto& t : store.tables(row.id))
    j["tables"].push_back({{"id", t.id}, {"method", t.method}, {"n", t.n}, {"accuracy", nlohmann::json::parse(t.accuracy_json, nullptr, false)}});
  for (const auto& e : store.events(row.id))
    j["events"].push_back({{"at", e.at}, {"kind", e.kind}, {"from", e.from_state}, {"to", e.to_state}, {"detail", e.detail}});
  std::cout << j.dump(2) << "\n";
}

// The campaign's first lines: what, where, its state and why, when; the specimen and the notes
// the lab recorded with it (with the plan, or changed since: db/campaign_record.hpp).
void print_heading(db::ReadSource& store, const db::CampaignRow& row) {
  const std::string why = store.state_reason(row.id, row.state);
  std::cout << "campaign " << row.id << ": " << domain::to_string(row.kind) << " on " << store.rig_name(row.rig_id) << ", " << domain::to_string(row.state)
            << (why.empty() ? "" : ": " + why) << "\n"
            << "  created " << utc_time(row.created_at) << ", updated " << utc_time(row.updated_at) << "\n";
  const db::CampaignRecord record = db::campaign_record(store, row);
  if (!record.specimen.empty()) std::cout << "  specimen: " << record.specimen << "\n";
  if (!record.notes.empty()) {
    std::string notes = record.notes;  // its lines under its first
    for (std::size_t at = notes.find('\n'); at != std::string::npos; at = notes.find('\n', at + 1)) notes.insert(at + 1, "         ");
    std::cout << "  notes: " << notes << "\n";
  }
  if (!record.changed_at.empty()) std::cout << "  (record changed " << utc_time(record.changed_at) << ")\n";
}

// Every event, a sentence each, under the date it happened (UTC).
void print_events(db::ReadSource& store, const db::CampaignRow& row) {
  std::cout << "  events (oldest first; times in UTC):\n";
  auto events = store.events(row.id);
  std::erase_if(events, [](const db::EventRow& e) { return e.kind == "gap"; });  // one per hole: the "gaps" summary says it in one line
  std::size_t width = 0;
  for (const auto& e : events) width = std::max(width, e.kind.size());
  std::string day;
  for (const auto& e : events) {
    if (const std::string d = e.at.substr(0, 10); d != day) std::cout << "    " << (day = d) << "\n";
    std::cout << "      " << event_line(e, width) << "\n";
  }
}

int show_campaign(db::ReadSource& store, const db::CampaignRow& row, bool as_json) {
  if (as_json) {
    show_json(store, row);
    return 0;
  }
  print_heading(store, row);
  for (const auto& r : store.runs(row.id))
    std::cout << "  run " << r.id << (r.role == "validation" ? " (validation)" : "") << ": " << r.state << ", " << r.samples << " samples, " << r.nodes
              << " FOT nodes\n";
  for (const domain::TrainingEvent& t : db::events_of<domain::TrainingEvent>(store, row.id)) std::cout << "  training: " << t.why << "\n";
  for (const auto& t : store.tables(row.id)) {
    const std::string acc = accuracy_line(t.accuracy_json), held = heldout_line(t.accuracy_json);
    std::cout << "  table " << t.id << ": " << t.method << ", n = " << t.n << ", " << round_g(t.range_lo) << "–" << round_g(t.range_hi) << " mm"
              << (acc.empty() ? "" : ", own samples " + acc) << (held.empty() ? "" : "; held-out " + held) << "\n";
  }
  for (const domain::RecommendationEvent& r : db::events_of<domain::RecommendationEvent>(store, row.id))
    std::cout << "  recommended: table " << r.table << ": " << r.why << "\n";
  if (const auto loops = store.loops(row.id); !loops.empty())
    std::cout << "  " << loops.size() << " closed cycle(s) with their figures (--json, or hystlab loops on a run's CSV)\n";
  print_sweep(store, row);
  print_events(store, row);
  return 0;
}
// hystlab campaign record ID --specimen ... --notes ...: POST /api/campaigns/ID/record.
int record_cmd(const Args& args, std::int64_t id) {
  refuse_db_option(args, "campaign record");
  const Options opt(rest(args, 2), {"specimen", "notes", "notes-file", "daemon", "token"}, {});
  if (opt.has("notes") && opt.has("notes-file")) throw CliError("give --notes or --notes-file, not both");
  nlohmann::json body = nlohmann::json::object();
  if (opt.has("specimen")) body["specimen"] = opt.get("specimen");
  if (opt.has("notes")) body["notes"] = opt.get("notes");
  if (opt.has("notes-file")) body["notes"] = read_file(opt.get("notes-file"));
  if (body.empty()) throw CliError("campaign record: give --specimen, --notes (or --notes-file), or both");
  const auto c = post_to_daemon(daemon_address(opt), "/api/campaigns/" + std::to_string(id) + "/record", body.dump());
  const auto text = [&](const char* k) { return c.contains(k) && c[k].is_string() ? "'" + c[k].get<std::string>() + "'" : std::string("none"); };
  std::cout << "campaign " << id << " recorded: specimen " << text("specimen") << ", notes " << text("notes") << "\n";
  return 0;
}
}  // namespace

int run_campaign_cmd(const Args& args) {
  if (print_help_if_asked(args, kCampaignHelp) || args.empty()) {
    if (args.empty()) std::cout << kCampaignHelp;
    return args.empty() ? 2 : 0;
  }
  const std::string verb = args[0];
  if (verb == "submit" || verb == "preview") {
    refuse_db_option(args, "campaign " + verb);
    const Options opt(rest(args, 1), {"plan", "rig", "daemon", "token"}, {});
    nlohmann::json body{{"plan", load_plan(opt.require("plan"))}};
    if (opt.has("rig")) body["rig"] = opt.get("rig");
    const DaemonAddress daemon = daemon_address(opt);
    if (verb == "preview") return print_preview(post_to_daemon(daemon, "/api/plans/preview", body.dump()));
    const auto c = post_to_daemon(daemon, "/api/campaigns", body.dump());
    const std::string state = c.value("state", "");  // the daemon may have started it before it answered
    std::cout << "campaign " << c.value("id", std::int64_t{0}) << " queued (" << c.value("kind", "") << " on '" << c.value("rig", "") << "'"
              << (state == "queued" ? "" : "; now " + state) << ")\n";
    return 0;
  }
  if (verb == "list") {
    const Options opt(rest(args, 1), {"db"}, {});
    db::Store store = open_store(opt);
    std::vector<std::vector<std::string>> rows;
    for (const auto& c : store.campaigns())
      rows.push_back({std::to_string(c.id), domain::to_string(c.kind), domain::to_string(c.state), utc_time(c.updated_at)});
    std::cout << aligned_table({{"id", true}, {"kind"}, {"state"}, {"updated"}}, rows);
    return 0;
  }
  const bool command = verb == "pause" || verb == "resume" || verb == "abort" || verb == "estop";
  if (!command && verb != "show" && verb != "record") throw CliError("unknown campaign verb '" + verb + "' (see --help)");
  const std::int64_t id = id_arg(args, 1, "campaign ID");
  if (verb == "record") return record_cmd(args, id);
  if (command) {
    refuse_db_option(args, "campaign " + verb);
    const Options opt(rest(args, 2), {"daemon", "token"}, {});
    const auto a = post_to_daemon(daemon_address(opt), "/api/campaigns/" + std::to_string(id) + "/" + verb, "");
    std::cout << verb << " " << (a.value("result", "") == "done" ? "done" : "sent") << ": campaign " << id << " (" << a.value("state", "") << ": "
              << a.value("reason", "") << ")\n";
    return 0;
  }
  const Options opt(rest(args, 2), {"db"}, {"json"});
  db::Store store = open_store(opt);
  const auto row = store.campaign(id);
  if (!row) throw CliError("no campaign " + std::to_string(id));
  return show_campaign(store, *row, opt.has("json"));
}

int run_tables_cmd(const Args& args) {
  if (print_help_if_asked(args, kTablesHelp) || args.empty()) {
    if (args.empty()) std::cout << kTablesHelp;
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "list") {
    const Options opt(rest(args, 1), {"db"}, {});
    db::Store store = open_store(opt);
    list_tables(store);
    return 0;
  }
  if (args[0] != "export") throw CliError("unknown tables verb '" + args[0] + "' (see --help)");
  const std::int64_t id = id_arg(args, 1, "table ID");
  const Options opt(rest(args, 2), {"db", "output", "format"}, {});
  const std::string format = opt.get("format", "json");
  if (!fmu::is_export_format(format)) throw CliError("--format: '" + format + "' is not " + std::string(fmu::kExportFormats));
  db::Store store = open_store(opt);
  const auto doc = store.table_document(id);
  if (!doc) throw CliError("no table " + std::to_string(id));
  if (format == "json") {  // the stored document as it is (its provenance and scores included)
    write_output(opt.get("output"), nlohmann::json::parse(*doc).dump(2) + "\n");
    return 0;
  }
  write_export(*doc, format, "hystlab_table_" + std::to_string(id), opt.get("output"));
  return 0;
}

}  // namespace hystlab::cli
