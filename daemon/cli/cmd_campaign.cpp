// hystlab campaign / tables / runs: the daemon's records, read and commanded through the db file
// (until the HTTP API lands). Commands are queued for hystlabd, which acts on them within 0.1 s.
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "hystlab/daemon/plan.hpp"
#include "hystlab/db/store.hpp"

namespace hystlab::cli {
namespace {
const char* kCampaignHelp = R"(usage: hystlab campaign submit --plan P.json [--rig NAME] [--db hystlab.db]
       hystlab campaign list [--db hystlab.db]
       hystlab campaign show ID [--db hystlab.db]
       hystlab campaign pause|resume|abort|estop ID [--db hystlab.db]

Campaigns run on hystlabd's rigs one after another. submit validates the plan (an error names the
field) and queues it; pause holds the rig; resume continues (after a long pause, or for an
interrupted campaign, with a wipe-out preamble and the rows not yet measured); abort drives to
the safe position; estop triggers the rig's e-stop at once (no motion). The rig defaults to the only one the daemon has. A waveform plan may give "points_csv": a CSV
file (beside the plan) whose displacement_mm column is the input, e.g. a random validation path.
)";
const char* kTablesHelp = R"(usage: hystlab tables list [--db hystlab.db]
       hystlab tables export ID [-o T.json] [--db hystlab.db]
)";
const char* kRunsHelp = R"(usage: hystlab runs export RUN_ID [-o X.csv] [--db hystlab.db]

Writes the run's samples as CSV: time_s,command_mm,displacement_mm,force_N,status.
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

std::int64_t rig_for(db::Store& store, const Options& opt) {
  if (opt.has("rig")) return store.upsert_rig(opt.get("rig"), "{}", now_iso8601());
  db::Statement st(store.database(), "SELECT id, name FROM rigs ORDER BY id");
  std::vector<std::pair<std::int64_t, std::string>> rigs;
  while (st.step()) rigs.emplace_back(st.column_int(0), st.column_text(1));
  if (rigs.empty()) return store.upsert_rig("simulated load frame", "{}", now_iso8601());  // hystlabd's default
  if (rigs.size() > 1) {
    std::string names;
    for (const auto& r : rigs) names += (names.empty() ? "" : ", ") + r.second;
    throw CliError("several rigs (" + names + "): choose one with --rig");
  }
  return rigs.front().first;
}
}  // namespace

int run_campaign_cmd(const Args& args) {
  if (print_help_if_asked(args, kCampaignHelp) || args.empty()) {
    if (args.empty()) std::cout << kCampaignHelp;
    return args.empty() ? 2 : 0;
  }
  const std::string verb = args[0];
  if (verb == "submit") {
    const Options opt(rest(args, 1), {"plan", "rig", "db"}, {});
    const std::string path = opt.require("plan");
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(read_file(path));
    } catch (const nlohmann::json::exception& e) {
      throw CliError(path + ": not valid JSON (" + e.what() + ")");
    }
    if (j.is_object() && j.contains("points_csv")) {  // a waveform from a CSV: its points go into the stored plan
      if (!j["points_csv"].is_string()) throw CliError(path + ": points_csv must be a file name");
      const std::filesystem::path csv = std::filesystem::path(path).parent_path() / j["points_csv"].get<std::string>();
      j["points_mm"] = Csv::load(csv.string()).column("displacement_mm");
      j.erase("points_csv");
    }
    const daemon::Plan plan = daemon::parse_plan(j);
    db::Store store(opt.get("db", "hystlab.db"));
    const auto id = store.create_campaign(rig_for(store, opt), plan.kind, j.dump(), now_iso8601());
    std::cout << "campaign " << id << " queued (" << plan.kind << ")\n";
    return 0;
  }
  if (verb == "list") {
    const Options opt(rest(args, 1), {"db"}, {});
    db::Store store(opt.get("db", "hystlab.db"));
    std::printf("%6s  %-9s %-12s %s\n", "id", "kind", "state", "updated");
    for (const auto& c : store.campaigns()) std::printf("%6lld  %-9s %-12s %s\n", static_cast<long long>(c.id), c.kind.c_str(), c.state.c_str(), c.updated_at.c_str());
    return 0;
  }
  const std::int64_t id = id_arg(args, 1, "campaign ID");
  const Options opt(rest(args, 2), {"db"}, {});
  db::Store store(opt.get("db", "hystlab.db"));
  const auto row = store.campaign(id);
  if (!row) throw CliError("no campaign " + std::to_string(id));
  if (verb == "show") {
    std::cout << "campaign " << row->id << ": " << row->kind << ", " << row->state << "\nplan: " << row->plan << "\nevents:\n";
    for (const auto& e : store.events(id))
      std::cout << "  " << e.at << "  " << e.kind << "  " << (e.from_state.empty() ? "" : e.from_state + " -> ") << e.to_state
                << (e.detail.empty() ? "" : "  " + e.detail) << "\n";
    db::Statement runs(store.database(), "SELECT id, state, (SELECT coalesce(sum(n),0) FROM sample_blocks WHERE run_id = runs.id), "
                                         "(SELECT count(*) FROM fot_nodes WHERE run_id = runs.id) FROM runs WHERE campaign_id = ?");
    runs.bind(1, id);
    while (runs.step())
      std::cout << "run " << runs.column_int(0) << ": " << runs.column_text(1) << ", " << runs.column_int(2) << " samples, "
                << runs.column_int(3) << " FOT nodes\n";
    db::Statement tables(store.database(), "SELECT id, method, n FROM tables WHERE campaign_id = ?");
    tables.bind(1, id);
    while (tables.step()) std::cout << "table " << tables.column_int(0) << ": " << tables.column_text(1) << ", n = " << tables.column_int(2) << "\n";
    return 0;
  }
  if (verb != "pause" && verb != "resume" && verb != "abort" && verb != "estop") throw CliError("unknown campaign verb '" + verb + "' (see --help)");
  store.add_command(id, verb, now_iso8601());
  std::cout << verb << " sent to campaign " << id << " (" << row->state << ")\n";
  return 0;
}

int run_tables_cmd(const Args& args) {
  if (print_help_if_asked(args, kTablesHelp) || args.empty()) {
    if (args.empty()) std::cout << kTablesHelp;
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "list") {
    const Options opt(rest(args, 1), {"db"}, {});
    db::Store store(opt.get("db", "hystlab.db"));
    db::Statement st(store.database(), "SELECT id, coalesce(campaign_id, 0), method, n, range_lo, range_hi, created_at FROM tables ORDER BY id");
    std::printf("%6s %9s  %-8s %4s  %-12s %s\n", "id", "campaign", "method", "n", "range (mm)", "created");
    while (st.step())
      std::printf("%6lld %9lld  %-8s %4lld  %5.3g..%-5.3g %s\n", static_cast<long long>(st.column_int(0)), static_cast<long long>(st.column_int(1)),
                  st.column_text(2).c_str(), static_cast<long long>(st.column_int(3)), st.column_double(4), st.column_double(5), st.column_text(6).c_str());
    return 0;
  }
  if (args[0] != "export") throw CliError("unknown tables verb '" + args[0] + "' (see --help)");
  const std::int64_t id = id_arg(args, 1, "table ID");
  const Options opt(rest(args, 2), {"db", "output"}, {});
  db::Store store(opt.get("db", "hystlab.db"));
  db::Statement st(store.database(), "SELECT document FROM tables WHERE id = ?");
  st.bind(1, id);
  if (!st.step()) throw CliError("no table " + std::to_string(id));
  write_output(opt.get("output"), nlohmann::json::parse(st.column_text(0)).dump(2) + "\n");
  return 0;
}

int run_runs_cmd(const Args& args) {
  if (print_help_if_asked(args, kRunsHelp) || args.empty() || args[0] != "export") {
    if (args.empty() || args[0] != "export") {
      std::cout << kRunsHelp;
      return 2;
    }
    return 0;
  }
  const std::int64_t id = id_arg(args, 1, "run ID");
  const Options opt(rest(args, 2), {"db", "output"}, {});
  db::Store store(opt.get("db", "hystlab.db"));
  if (store.max_seq(id) < 0) throw CliError("no samples for run " + std::to_string(id));
  std::string out = "time_s,command_mm,displacement_mm,force_N,status\n";
  store.for_each_sample(id, 0, std::int64_t{1} << 50, [&](const db::SampleRow& r) {
    out += format_number(r.t) + "," + format_number(r.cmd) + "," + format_number(r.disp) + "," + format_number(r.force) + "," +
           std::to_string(r.status) + "\n";
  });
  write_output(opt.get("output"), out);
  return 0;
}

}  // namespace hystlab::cli
