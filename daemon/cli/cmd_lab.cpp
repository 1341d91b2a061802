// hystlab lab campaigns|tables|show|compare: the lab database (PostgreSQL, every daemon's store
// replicated into it, docs/LAB.md) read across rigs and daemons. Read-only: nothing here writes.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <optional>

#include "cli_support.hpp"
#include "commands.hpp"
#include "event_text.hpp"
#include "hystlab/db/lab_reads.hpp"
#include "hystlab/domain/campaign.hpp"
#include "lab_access.hpp"

namespace hystlab::cli {
// Its own namespace: the unity build puts the verbs' files in one unit, and their helpers
// (round_g, scores_of, ...) would meet.
namespace lab_cmd {
namespace {
using nlohmann::json;

const char* kLabUsage = R"(usage: hystlab lab campaigns --pg URL [--lab NAME] [--daemon NAME] [--specimen TEXT] [--kind fot|waveform|sine] [--limit N] [--json]
       hystlab lab tables --pg URL [--lab NAME] [--daemon NAME] [--specimen TEXT] [--limit N] [--json]
       hystlab lab show DAEMON/ID --pg URL [--lab NAME] [--events N] [--json]
       hystlab lab compare --pg URL (--specimen TEXT | DAEMON/TABLE ...) [--lab NAME] [--json]
       (every one also: [--pg-password-file FILE])

The lab database, which every daemon with a lab.postgresql replicates its store into
(docs/LAB.md): every rig's campaigns and tables side by side, by daemon and specimen.
campaigns: one a row, the latest change first (daemon, rig, its id on that daemon, kind, state,
specimen, updated). tables: every identified table with its error on its own samples and held out
(on its campaign's validation run, which no table was built from). show: one campaign (DAEMON/ID:
the daemon's name and the campaign's id there): its plan, runs, tables and last events (--events,
default 20). compare: the tables of one specimen (or the ones named) ranked by their held-out
RMS error, with the other figures their scores hold, and which is best; a table without held-out
figures is listed after them, unranked. The filters match exactly. Times are in UTC.
A run's samples from the lab: hystlab runs export RUN_ID --pg URL --daemon NAME (runs --help).

)";

std::string round_g(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}
std::string dash_if_empty(const std::string& s) { return s.empty() ? "-" : s; }
std::string lab_time(const std::string& pg_text) { return pg_text.empty() ? "-" : utc_time(iso_of_lab_time(pg_text)); }

// "DAEMON/ID": the daemon's name (which may hold '/') and a positive id after the last '/'.
std::pair<std::string, std::int64_t> daemon_and_id(const std::string& text, const char* what) {
  const auto slash = text.rfind('/');
  std::int64_t id = 0;
  if (slash != std::string::npos && slash > 0) {
    try {
      std::size_t used = 0;
      id = std::stoll(text.substr(slash + 1), &used);
      if (used != text.size() - slash - 1) id = 0;
    } catch (...) {
      id = 0;
    }
  }
  if (id <= 0) throw CliError(std::string(what) + " must be DAEMON/ID (a daemon's name, '/', a positive whole number), got '" + text + "'");
  return {text.substr(0, slash), id};
}

// A table's figures as its daemon scored it (models/table_score.hpp's accuracy_json, with the
// held-out block and the recommendation run_finish.cpp adds). nullopt: no such figure.
struct Figures {
  std::optional<double> rms, rms_pct, max, energy;
};
struct TableScores {
  Figures own, held;
  std::optional<std::int64_t> held_samples;
  bool recommended = false;
};
Figures figures_of(const json& block) {
  Figures f;
  if (!block.is_object()) return f;
  const auto number = [](const json& o, const char* k) { return o.contains(k) && o[k].is_number() ? std::optional<double>(o[k].get<double>()) : std::nullopt; };
  if (block.contains("overall") && block["overall"].is_object()) {
    const json& o = block["overall"];
    f.rms = number(o, "rms_N"), f.max = number(o, "max_N");
    if (const auto n = number(o, "rms_norm")) f.rms_pct = 100 * *n;
  }
  f.energy = number(block, "loop_energy_rel_error");
  if (f.energy) *f.energy *= 100;
  return f;
}
TableScores scores_of(const std::string& text) {
  TableScores s;
  const json a = json::parse(text.empty() ? "null" : text, nullptr, false);
  if (!a.is_object()) return s;
  s.own = figures_of(a);
  if (a.contains("held_out")) {
    s.held = figures_of(a["held_out"]);
    const json& o = a["held_out"].value("overall", json::object());
    if (o.is_object() && o.contains("samples") && o["samples"].is_number_integer()) s.held_samples = o["samples"].get<std::int64_t>();
  }
  s.recommended = a.value("recommended", false);
  return s;
}
std::string cell(const std::optional<double>& v) { return v ? round_g(*v) : "-"; }
json json_of(const std::optional<double>& v) { return v ? json(*v) : json(); }
json json_of(const Figures& f) {
  return {{"rms_N", json_of(f.rms)}, {"rms_pct_of_range", json_of(f.rms_pct)}, {"max_N", json_of(f.max)}, {"loop_energy_error_pct", json_of(f.energy)}};
}

db::LabFilter filter_of(const Options& opt, bool with_kind) {
  db::LabFilter f{opt.get("lab"), opt.get("daemon"), opt.get("specimen"), {}, opt.integer("limit", 200, 1, 100000)};
  if (with_kind && opt.has("kind")) {
    f.kind = opt.get("kind");
    if (!domain::campaign_kind_from(f.kind)) throw CliError("--kind: '" + f.kind + "' is not fot, waveform or sine");
  }
  return f;
}

int list_campaigns(db::LabReads& lab, const Options& opt) {
  const auto campaigns = lab.campaigns(filter_of(opt, true));
  if (opt.has("json")) {
    json j = json::array();
    for (const auto& c : campaigns)
      j.push_back({{"lab", c.lab},
                   {"daemon", c.daemon},
                   {"rig", c.rig},
                   {"id", c.id},
                   {"kind", c.kind},
                   {"state", c.state},
                   {"specimen", c.specimen.empty() ? json() : json(c.specimen)},
                   {"created_at", iso_of_lab_time(c.created_at)},
                   {"updated_at", iso_of_lab_time(c.updated_at)}});
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::vector<std::vector<std::string>> rows;
  for (const auto& c : campaigns)
    rows.push_back({c.daemon, dash_if_empty(c.rig), std::to_string(c.id), c.kind, c.state, dash_if_empty(c.specimen), lab_time(c.updated_at)});
  std::cout << aligned_table({{"daemon"}, {"rig"}, {"campaign", true}, {"kind"}, {"state"}, {"specimen"}, {"updated"}}, rows);
  if (campaigns.empty()) std::cout << "(no campaign matches)\n";
  return 0;
}

int list_tables(db::LabReads& lab, const Options& opt) {
  const auto tables = lab.tables(filter_of(opt, false));
  if (opt.has("json")) {
    json j = json::array();
    for (const auto& t : tables) {
      const TableScores s = scores_of(t.accuracy);
      j.push_back({{"daemon", t.daemon},
                   {"id", t.id},
                   {"campaign", t.campaign ? json(t.campaign) : json()},
                   {"specimen", t.specimen.empty() ? json() : json(t.specimen)},
                   {"method", t.method},
                   {"n", t.n},
                   {"range_mm", {t.range_lo, t.range_hi}},
                   {"own", json_of(s.own)},
                   {"held_out", json_of(s.held)},
                   {"recommended", s.recommended},
                   {"created_at", iso_of_lab_time(t.created_at)}});
    }
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::vector<std::vector<std::string>> rows;
  bool star = false;
  for (const auto& t : tables) {
    const TableScores s = scores_of(t.accuracy);
    star = star || s.recommended;
    rows.push_back({t.daemon, std::to_string(t.id), t.campaign ? std::to_string(t.campaign) : "-", dash_if_empty(t.specimen), t.method, std::to_string(t.n),
                    round_g(t.range_lo) + ".." + round_g(t.range_hi), cell(s.own.rms), cell(s.held.rms), cell(s.held.max), s.recommended ? "*" : "",
                    lab_time(t.created_at)});
  }
  std::cout << aligned_table({{"daemon"},
                              {"table", true},
                              {"campaign", true},
                              {"specimen"},
                              {"method"},
                              {"n", true},
                              {"range (mm)"},
                              {"RMS (N)", true},
                              {"held-out RMS (N)", true},
                              {"held-out max (N)", true},
                              {""},
                              {"created"}},
                             rows);
  if (tables.empty()) std::cout << "(no table matches)\n";
  if (star) std::cout << "*: the table its campaign recommends (the lowest held-out error there)\n";
  return 0;
}

// The plan's fields in one line: scalars as key=value, arrays by their length.
std::string plan_summary(const std::string& plan_text) {
  const json plan = json::parse(plan_text.empty() ? "null" : plan_text, nullptr, false);
  if (!plan.is_object()) return plan_text;
  std::string out;
  for (const auto& [k, v] : plan.items()) {
    if (k == "specimen" || k == "notes") continue;  // said on their own lines
    std::string value = v.is_string() ? v.get<std::string>() : v.is_array() && v.size() > 4 ? "[" + std::to_string(v.size()) + " values]" : v.dump();
    if (value.size() > 60) value = value.substr(0, 57) + "...";
    out += (out.empty() ? "" : ", ") + k + "=" + value;
  }
  return out;
}

db::EventRow event_row(const db::LabEvent& e) { return {e.id, iso_of_lab_time(e.at), e.kind, e.from_state, e.to_state, e.detail}; }

int show_campaign(db::LabReads& lab, const Args& args, const Options& opt) {
  if (args.size() < 2 || args[1].starts_with("-")) throw CliError("lab show: give the campaign as DAEMON/ID (hystlab lab campaigns lists them)");
  const auto [daemon_name, id] = daemon_and_id(args[1], "lab show");
  const db::LabDaemon daemon = lab_daemon(lab, daemon_name, opt.get("lab"));
  const auto c = lab.campaign(daemon.name, id);
  if (!c) throw CliError("no campaign " + std::to_string(id) + " on daemon '" + daemon.name + "' in the lab database");
  const int last_events = opt.integer("events", 20, 0, 1000000);
  const auto runs = lab.runs(c->daemon_id, id);
  auto events = lab.events(c->daemon_id, id, 1000000);
  const auto tables = lab.tables({c->lab, c->daemon, {}, {}, 100000});
  std::vector<db::LabTable> mine;
  std::copy_if(tables.begin(), tables.end(), std::back_inserter(mine), [id = id](const db::LabTable& t) { return t.campaign == id; });
  if (opt.has("json")) {
    json j{{"lab", c->lab},
           {"daemon", c->daemon},
           {"id", c->id},
           {"rig", c->rig},
           {"kind", c->kind},
           {"state", c->state},
           {"specimen", c->specimen.empty() ? json() : json(c->specimen)},
           {"created_at", iso_of_lab_time(c->created_at)},
           {"updated_at", iso_of_lab_time(c->updated_at)},
           {"plan", json::parse(c->plan.empty() ? "null" : c->plan, nullptr, false)},
           {"runs", json::array()},
           {"tables", json::array()},
           {"events", json::array()}};
    for (const auto& r : runs)
      j["runs"].push_back({{"id", r.id}, {"role", r.role}, {"state", r.state}, {"samples", r.samples}, {"rig_kind", r.shaker ? "shaker" : "load frame"}});
    for (const auto& t : mine) {
      const TableScores s = scores_of(t.accuracy);
      j["tables"].push_back(
          {{"id", t.id}, {"method", t.method}, {"n", t.n}, {"own", json_of(s.own)}, {"held_out", json_of(s.held)}, {"recommended", s.recommended}});
    }
    const std::size_t from = events.size() > static_cast<std::size_t>(last_events) ? events.size() - static_cast<std::size_t>(last_events) : 0;
    for (std::size_t k = from; k < events.size(); ++k) {
      const auto& e = events[k];
      j["events"].push_back({{"at", iso_of_lab_time(e.at)}, {"kind", e.kind}, {"from", e.from_state}, {"to", e.to_state}, {"detail", e.detail}});
    }
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "campaign " << c->daemon << "/" << c->id << " (lab " << c->lab << "): " << c->kind << " on " << dash_if_empty(c->rig) << ", " << c->state << "\n"
            << "  created " << lab_time(c->created_at) << ", updated " << lab_time(c->updated_at) << "\n";
  if (!c->specimen.empty()) std::cout << "  specimen: " << c->specimen << "\n";
  std::cout << "  plan: " << plan_summary(c->plan) << "\n";
  for (const auto& r : runs)
    std::cout << "  run " << r.id << (r.role == "validation" ? " (validation)" : "") << ": " << dash_if_empty(r.state) << ", " << r.samples << " samples"
              << (r.samples > 0 ? (r.shaker ? " (shaker)" : " (load frame)") : "") << "\n";
  for (const auto& t : mine) {
    const TableScores s = scores_of(t.accuracy);
    std::cout << "  table " << t.id << ": " << t.method << ", n = " << t.n << ", " << round_g(t.range_lo) << "–" << round_g(t.range_hi) << " mm";
    if (s.own.rms) std::cout << ", own samples RMS " << cell(s.own.rms) << " N, max " << cell(s.own.max) << " N";
    if (s.held.rms) std::cout << "; held-out RMS " << cell(s.held.rms) << " N, max " << cell(s.held.max) << " N" << (s.recommended ? " (recommended)" : "");
    std::cout << "\n";
  }
  std::erase_if(events, [](const db::LabEvent& e) { return e.kind == "gap"; });  // one per hole: "gaps" says it in one line
  const std::size_t from = events.size() > static_cast<std::size_t>(last_events) ? events.size() - static_cast<std::size_t>(last_events) : 0;
  std::cout << "  events (" << (from > 0 ? "the last " + std::to_string(events.size() - from) + " of " + std::to_string(events.size()) : "oldest first")
            << "; times in UTC):\n";
  std::size_t width = 0;
  for (std::size_t k = from; k < events.size(); ++k) width = std::max(width, events[k].kind.size());
  std::string day;
  for (std::size_t k = from; k < events.size(); ++k) {
    const db::EventRow e = event_row(events[k]);
    if (const std::string d = e.at.substr(0, 10); d != day) std::cout << "    " << (day = d) << "\n";
    std::cout << "      " << event_line(e, width) << "\n";
  }
  return 0;
}

// compare: the tables chosen, their rigs, ranked by held-out RMS (those without it after, by id).
struct Entry {
  db::LabTable table;
  std::string rig;
  TableScores s;
};

int compare_tables(db::LabReads& lab, const Args& args, const Options& opt, std::size_t positional) {
  const std::string lab_name = opt.get("lab");
  std::vector<Entry> entries;
  if (opt.has("specimen") == (positional > 0)) throw CliError("lab compare: give --specimen TEXT or DAEMON/TABLE ids, one of the two");
  if (opt.has("specimen")) {
    for (auto& t : lab.tables({lab_name, {}, opt.get("specimen"), {}, 100000})) entries.push_back({std::move(t), {}, {}});
    if (entries.empty()) throw CliError("no table of specimen '" + opt.get("specimen") + "' in the lab database (hystlab lab tables lists them)");
  } else {
    for (std::size_t k = 1; k <= positional; ++k) {
      const auto [name, id] = daemon_and_id(args[k], "lab compare");
      const db::LabDaemon d = lab_daemon(lab, name, lab_name);
      const auto of_daemon = lab.tables({d.lab, d.name, {}, {}, 100000});
      const auto it = std::find_if(of_daemon.begin(), of_daemon.end(), [id = id](const db::LabTable& t) { return t.id == id; });
      if (it == of_daemon.end()) throw CliError("no table " + std::to_string(id) + " on daemon '" + d.name + "' in the lab database");
      entries.push_back({*it, {}, {}});
    }
  }
  std::map<std::pair<int, std::int64_t>, std::string> rigs;  // (daemon, campaign) -> rig
  for (Entry& e : entries) {
    e.s = scores_of(e.table.accuracy);
    const auto key = std::pair{e.table.daemon_id, e.table.campaign};
    if (!rigs.contains(key)) {
      const auto c = e.table.campaign ? lab.campaign(e.table.daemon, e.table.campaign) : std::nullopt;
      rigs[key] = c ? c->rig : "";
    }
    e.rig = rigs[key];
  }
  std::stable_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    if (a.s.held.rms.has_value() != b.s.held.rms.has_value()) return a.s.held.rms.has_value();
    if (a.s.held.rms && *a.s.held.rms != *b.s.held.rms) return *a.s.held.rms < *b.s.held.rms;
    return std::pair(a.table.daemon, a.table.id) < std::pair(b.table.daemon, b.table.id);
  });
  const std::size_t ranked = static_cast<std::size_t>(std::count_if(entries.begin(), entries.end(), [](const Entry& e) { return e.s.held.rms.has_value(); }));
  const auto name_of = [](const Entry& e) { return e.table.daemon + "/" + std::to_string(e.table.id); };
  if (opt.has("json")) {
    json j{{"tables", json::array()}, {"best", ranked > 0 ? json(name_of(entries.front())) : json()}};
    for (std::size_t k = 0; k < entries.size(); ++k) {
      const Entry& e = entries[k];
      j["tables"].push_back({{"rank", k < ranked ? json(k + 1) : json()},
                             {"daemon", e.table.daemon},
                             {"table", e.table.id},
                             {"rig", e.rig.empty() ? json() : json(e.rig)},
                             {"campaign", e.table.campaign},
                             {"specimen", e.table.specimen},
                             {"method", e.table.method},
                             {"n", e.table.n},
                             {"held_out", json_of(e.s.held)},
                             {"held_out_samples", e.s.held_samples ? json(*e.s.held_samples) : json()},
                             {"own", json_of(e.s.own)},
                             {"recommended_by_campaign", e.s.recommended}});
    }
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::vector<std::vector<std::string>> rows;
  for (std::size_t k = 0; k < entries.size(); ++k) {
    const Entry& e = entries[k];
    rows.push_back({k < ranked ? std::to_string(k + 1) : "-", name_of(e), dash_if_empty(e.rig), e.table.campaign ? std::to_string(e.table.campaign) : "-",
                    dash_if_empty(e.table.specimen), e.table.method, std::to_string(e.table.n), cell(e.s.held.rms), cell(e.s.held.rms_pct), cell(e.s.held.max),
                    cell(e.s.held.energy), cell(e.s.own.rms), e.s.recommended ? "*" : ""});
  }
  std::cout << aligned_table({{"rank", true},
                              {"table"},
                              {"rig"},
                              {"campaign", true},
                              {"specimen"},
                              {"method"},
                              {"n", true},
                              {"held-out RMS (N)", true},
                              {"% range", true},
                              {"held-out max (N)", true},
                              {"energy err (%)", true},
                              {"own RMS (N)", true},
                              {""}},
                             rows);
  if (ranked == 0) {
    std::cout << "no best: none of these tables has held-out figures (its campaign had no validation run)\n";
  } else {
    const Entry& best = entries.front();
    std::cout << "best: " << name_of(best) << " (" << best.table.method << ", n = " << best.table.n << (best.rig.empty() ? "" : ", on " + best.rig)
              << "), held-out RMS " << cell(best.s.held.rms) << " N";
    if (ranked > 1) std::cout << "; next " << name_of(entries[1]) << ", " << cell(entries[1].s.held.rms) << " N";
    std::cout << "\n";
  }
  if (ranked < entries.size()) std::cout << "-: not ranked (no held-out figures: its campaign had no validation run)\n";
  if (std::any_of(entries.begin(), entries.end(), [](const Entry& e) { return e.s.recommended; })) std::cout << "*: the table its own campaign recommends\n";
  return 0;
}
}  // namespace

int run(const Args& args) {
  static const std::string help = std::string(kLabUsage) + kLabConnectionHelp;
  if (print_help_if_asked(args, help.c_str()) || args.empty()) {
    if (args.empty()) std::cout << help;
    return args.empty() ? 2 : 0;
  }
  const std::string verb = args[0];
  const std::set<std::string> connection{"pg", "pg-password-file", "lab"};
  const auto with = [&](std::initializer_list<const char*> more) {
    std::set<std::string> s = connection;
    s.insert(more.begin(), more.end());
    return s;
  };
  std::size_t skip = 1;  // the verb, and the ids before the options
  if (verb == "show") skip = 2;
  if (verb == "compare")
    while (skip < args.size() && !args[skip].starts_with("-")) ++skip;
  const Args rest(args.begin() + static_cast<std::ptrdiff_t>(std::min(skip, args.size())), args.end());
  std::optional<Options> opt;
  if (verb == "campaigns")
    opt.emplace(rest, with({"daemon", "specimen", "kind", "limit"}), std::set<std::string>{"json"});
  else if (verb == "tables")
    opt.emplace(rest, with({"daemon", "specimen", "limit"}), std::set<std::string>{"json"});
  else if (verb == "show")
    opt.emplace(rest, with({"events"}), std::set<std::string>{"json"});
  else if (verb == "compare")
    opt.emplace(rest, with({"specimen"}), std::set<std::string>{"json"});
  else
    throw CliError("unknown lab verb '" + verb + "' (campaigns, tables, show, compare; see --help)");
  if (verb == "show" && (args.size() < 2 || args[1].starts_with("-")))
    throw CliError("lab show: give the campaign as DAEMON/ID (hystlab lab campaigns lists them)");
  // The command's own errors before the connection's.
  if (verb == "campaigns" || verb == "tables") (void)filter_of(*opt, verb == "campaigns");
  if (verb == "compare" && opt->has("specimen") == (skip > 1)) throw CliError("lab compare: give --specimen TEXT or DAEMON/TABLE ids, one of the two");
  const auto pg = connect_lab(*opt);
  db::LabReads lab(*pg);
  try {
    if (verb == "campaigns") return list_campaigns(lab, *opt);
    if (verb == "tables") return list_tables(lab, *opt);
    if (verb == "show") return show_campaign(lab, args, *opt);
    return compare_tables(lab, args, *opt, skip - 1);
  } catch (const db::PgError& e) {
    throw CliError("the lab database: " + one_line(e.what()));
  }
}
}  // namespace lab_cmd

int run_lab_cmd(const Args& args) { return lab_cmd::run(args); }

}  // namespace hystlab::cli
