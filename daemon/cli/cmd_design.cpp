// hystlab design: where the next FOT rows should go on a specimen already identified (issue 41;
// the rule is models/fot_design.hpp's).
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "hystlab/models/fot_design.hpp"
#include "hystlab/models/preisach_fit.hpp"

namespace hystlab::cli {
namespace {

const char* kDesignHelp = R"(usage: hystlab design --table T.json --budget-s S [--data X.csv] [--ramp-mm-s R] [--settle-s S]
                      [--target-rms-n E] [--max-rows K] [-o DESIGN.json]

Suggests the rows (tops α of first-order reversals, each measured down to the bottom of the range)
of a next FOT campaign on a specimen already identified: the rows that remove the most of the
table's estimated error per second of rig time. The error of a band between two nodes is its
interpolation error (where the Everett surface bends) and, with --data (the record the table was
fitted to, columns displacement_mm and force_N), the least-squares fit's own uncertainty of its
cells. A row up to α and back costs 2·α/R plus the settle (R: --ramp-mm-s, default 0.18 mm/s).
It stops at the budget, at the target RMS error (--target-rms-n), or when a row would remove less
than 2 % of the error left, and says which. Prints the rows and the grid with their nodes added
(the --nodes of `hystlab fit` and of a plan's grid); -o writes them as JSON.
)";

// The figures as a reader wants them: 4 significant digits (the JSON keeps them whole).
std::string g4(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

nlohmann::json design_json(const models::Design& d) {
  nlohmann::json rows = nlohmann::json::array();
  for (const models::DesignRow& r : d.rows)
    rows.push_back({{"alpha_mm", r.alpha_mm}, {"seconds", r.seconds}, {"error_N", r.error_N}, {"rms_after_N", r.rms_after_N}, {"why", r.why}});
  return {{"rows", rows}, {"rms_before_N", d.rms_before_N}, {"seconds", d.seconds}, {"nodes", d.nodes}, {"stopped", d.stopped}};
}

}  // namespace

int run_design(const Args& args) {
  if (print_help_if_asked(args, kDesignHelp)) return 0;
  const Options opt(args, {"table", "budget-s", "data", "ramp-mm-s", "settle-s", "target-rms-n", "max-rows", "output"}, {});
  const std::string path = opt.require("table");
  const models::TableDocument doc = read_table_file(path);
  models::DesignOptions o;
  if (!opt.has("budget-s")) throw CliError("missing required option --budget-s (the rig time the new rows may take, s)");
  o.budget_s = opt.number("budget-s", 0.0);
  o.ramp_mm_s = opt.number("ramp-mm-s", o.ramp_mm_s);
  o.settle_s = opt.number("settle-s", o.settle_s);
  o.target_rms_N = opt.number("target-rms-n", 0.0);
  o.max_rows = opt.integer("max-rows", o.max_rows, 1, 1000);
  std::vector<double> sigma;
  if (opt.has("data")) {  // the fit's σ per cell, on the table's own grid
    const Csv csv = Csv::load(opt.get("data"));
    const auto x = csv.column("displacement_mm"), y = csv.column("force_N");
    sigma = models::fit_preisach(x, y, doc.table.grid()).chosen.cell_sigma;
  }
  models::Design d;
  try {
    d = models::design_rows(doc.table, sigma, o);
  } catch (const std::invalid_argument& e) {  // "design: budget_s ..." -> the option's own name
    std::string m = e.what();
    for (const auto& [field, option] :
         {std::pair{"budget_s", "--budget-s"}, {"ramp_mm_s", "--ramp-mm-s"}, {"settle_s", "--settle-s"}, {"target_rms_N", "--target-rms-n"}})
      if (const auto at = m.find(field); at != std::string::npos) m.replace(at, std::string(field).size(), "option " + std::string(option));
    throw CliError(m);
  }
  std::cout << "table " << path << ": n = " << doc.table.grid().n << ", estimated RMS error " << g4(d.rms_before_N) << " N"
            << (sigma.empty() ? " (interpolation only: no --data)" : " (interpolation and the fit's uncertainty)") << "\n";
  for (std::size_t k = 0; k < d.rows.size(); ++k) {
    const models::DesignRow& r = d.rows[k];
    std::cout << "row " << k + 1 << ": up to " << g4(r.alpha_mm) << " mm, " << g4(r.seconds) << " s; " << r.why << "; then " << g4(r.rms_after_N) << " N\n";
  }
  std::cout << d.rows.size() << " rows, " << g4(d.seconds) << " s of rig time; stopped: " << d.stopped << "\nnodes:";
  for (std::size_t k = 0; k < d.nodes.size(); ++k) std::cout << (k == 0 ? " " : ",") << format_number(d.nodes[k]);
  std::cout << "\n";
  if (opt.has("output")) {
    write_file(opt.get("output"), design_json(d).dump(2) + "\n");
    std::cout << "wrote " << opt.get("output") << "\n";
  }
  return 0;
}

}  // namespace hystlab::cli
