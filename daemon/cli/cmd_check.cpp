// hystlab check / compare: numbers about a data set and about a model against it.
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli_support.hpp"
#include "commands.hpp"
#include "hystlab/models/accuracy.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/representation_checks.hpp"

namespace hystlab::cli {

namespace {
const char* kCheckHelp = R"(usage: hystlab check --data X.csv [--dead-band MM] [--tolerance MM]

Can a Preisach model represent this record (columns displacement_mm, force_N)? Reports
wiping-out (force on returning to an earlier turning point against the force there) and
congruency (minor loops between the same extrema, compared after a vertical shift), in N and
normalised by the force range. --dead-band: reversals smaller than this are noise (default 0.5 %
of the displacement range); --tolerance: extrema that agree within it count as the same.
)";

const char* kCompareHelp = R"(usage: hystlab compare (--table T.json | --table-id ID | --model simplified [--params P.json])
                       (--data X.csv | --run RUN) [--clamp] [--db hystlab.db]

Runs the model on column displacement_mm of X.csv and compares with column force_N: RMS and max
error, normalised by the reference force range, per branch direction (ascending, descending) and
overall; the loop energy error when the input returns to where it began.
--table-id and --run take a table and a run's samples from hystlabd's database (--db): a
campaign's validation run re-scored against any table, later ones included, as the campaign
scored its own tables (the API: GET /api/tables/ID/score?run=RUN).
)";

std::string pct(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f %%", 100.0 * v);
  return buf;
}
}  // namespace

std::string accuracy_text(const models::AccuracyReport& r) {
  std::string out;
  char buf[200];
  std::snprintf(buf, sizeof buf, "%-11s %8s %12s %12s %10s %10s\n", "branch", "samples", "rms (N)", "max (N)", "rms/range", "max/range");
  out += buf;
  const std::pair<const char*, const models::ErrorStats*> rows[] = {{"overall", &r.overall}, {"ascending", &r.ascending}, {"descending", &r.descending}};
  for (const auto& [name, s] : rows) {
    std::snprintf(buf, sizeof buf, "%-11s %8zu %12.6g %12.6g %10s %10s\n", name, s->count, s->rms, s->max_abs, pct(s->rms_norm).c_str(),
                  pct(s->max_norm).c_str());
    out += buf;
  }
  out += "reference force range: " + format_number(r.reference_range) + " N\n";
  if (r.energy_rel_error)
    out += "loop energy: reference " + format_number(*r.energy_reference) + " N*mm, model " + format_number(*r.energy_model) + " N*mm, relative error " +
           pct(*r.energy_rel_error) + "\n";
  else
    out += "loop energy: not applicable (the input does not return to where it began)\n";
  return out;
}

int run_check(const Args& args) {
  if (print_help_if_asked(args, kCheckHelp)) return 0;
  const Options opt(args, {"data", "dead-band", "tolerance"}, {});
  const Csv csv = Csv::load(opt.require("data"));
  const auto x = csv.column("displacement_mm"), f = csv.column("force_N");
  models::RepresentationOptions ro;
  ro.dead_band = opt.number("dead-band", -1.0);
  ro.extremum_tolerance = opt.number("tolerance", -1.0);
  if (opt.has("dead-band") && ro.dead_band < 0) throw CliError("option --dead-band: must be >= 0");
  if (opt.has("tolerance") && ro.extremum_tolerance < 0) throw CliError("option --tolerance: must be >= 0");
  const models::RepresentationReport r = models::check_representation(x, f, ro);
  std::cout << "samples: " << x.size() << ", reversals: " << r.reversals << ", force range " << format_number(r.force_range) << " N\n"
            << "wiping-out: " << r.wiping_out.events << " returns to a turning point; deviation max " << format_number(r.wiping_out.max_deviation) << " N ("
            << pct(r.wiping_out.max_deviation_norm) << "), rms " << format_number(r.wiping_out.rms_deviation) << " N\n"
            << "congruency: " << r.congruency.loops << " closed minor loops, " << r.congruency.compared_pairs
            << " pairs with the same extrema; shape deviation max " << format_number(r.congruency.max_deviation) << " N ("
            << pct(r.congruency.max_deviation_norm) << "), rms " << format_number(r.congruency.rms_deviation) << " N\n";
  if (r.wiping_out.events == 0 || r.congruency.compared_pairs == 0)
    std::cout << "note: the record has too few closed minor loops to judge " << (r.wiping_out.events == 0 ? "wiping-out" : "congruency") << "\n";
  return 0;
}

int run_compare(const Args& args) {
  if (print_help_if_asked(args, kCompareHelp)) return 0;
  const Options opt(args, {"table", "table-id", "model", "params", "data", "run", "db"}, {"clamp"});
  if (opt.has("data") == opt.has("run")) throw CliError("give one of --data X.csv or --run RUN");
  LoadedModel m;
  std::unique_ptr<db::Store> store;
  if (opt.has("table-id") || opt.has("run")) {
    require_database(opt.get("db", "hystlab.db"));
    store = std::make_unique<db::Store>(opt.get("db", "hystlab.db"));
  }
  if (opt.has("table-id")) {
    if (opt.has("table") || opt.has("model")) throw CliError("give one of --table, --table-id or --model");
    const int id = opt.integer("table-id", 0, 1, 2000000000);
    const auto doc = store->table_document(id);
    if (!doc) throw CliError("--table-id: no table " + std::to_string(id) + " in " + opt.get("db", "hystlab.db"));
    auto t = models::table_from_json(*doc);
    m.lo = t.table.grid().lo, m.hi = t.table.grid().hi;
    m.description = "table " + std::to_string(id) + " (" + t.provenance.method + ", n = " + std::to_string(t.table.grid().n) + ")";
    m.model = std::make_unique<models::PreisachModel>(std::move(t.table));
  } else {
    m = load_model(opt);
  }
  std::string path;
  std::vector<double> x, ref;
  std::vector<std::size_t> lines;
  if (opt.has("run")) {
    const int run = opt.integer("run", 0, 1, 2000000000);
    const auto info = store->run(run);
    if (!info) throw CliError("--run: no run " + std::to_string(run) + " in " + opt.get("db", "hystlab.db"));
    store->for_each_sample(run, 0, std::int64_t{1} << 50, [&](const db::SampleRow& r) {
      x.push_back(r.disp);
      ref.push_back(r.force);
      lines.push_back(static_cast<std::size_t>(r.seq));
    });
    path = "run " + std::to_string(run) + (info->role == "validation" ? " (validation)" : "");
    if (x.size() < 2) throw CliError("--run: run " + std::to_string(run) + " has " + std::to_string(x.size()) + " sample(s)");
  } else {
    path = opt.require("data");
    const Csv csv = Csv::load(path);
    x = csv.column("displacement_mm"), ref = csv.column("force_N");
    for (std::size_t k = 0; k < x.size(); ++k) lines.push_back(csv.line_of(k));
  }
  // A run is scored as the campaign scored it: inputs beyond the table's range clamped, and counted.
  if (m.hi > m.lo && !opt.has("clamp") && !opt.has("run"))
    for (std::size_t k = 0; k < x.size(); ++k)
      if (x[k] < m.lo || x[k] > m.hi)
        throw CliError(path + (opt.has("run") ? ": sample " : ": line ") + std::to_string(lines[k]) + ": displacement " + format_number(x[k]) +
                       " mm is outside the table's range (--clamp clamps and counts)");
  std::vector<double> y(x.size());
  m.model->evaluate(x, y);
  std::cout << "model: " << m.description << "\ndata: " << path << " (" << x.size() << " samples)\n" << accuracy_text(models::compare(x, ref, y));
  if (const auto sat = m.model->saturation_count())
    std::cout << sat << " input(s) beyond the table's range " << format_number(m.lo) << ".." << format_number(m.hi) << " mm were clamped\n";
  return 0;
}

}  // namespace hystlab::cli
