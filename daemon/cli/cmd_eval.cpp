// hystlab eval / invert: drive a model with a series from a CSV file.
#include <iostream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/inverse.hpp"
#include "hystlab/models/preisach_model.hpp"

namespace hystlab::cli {

namespace {
const char* kEvalHelp = R"(usage: hystlab eval (--table T.json | --model simplified [--params P.json]) --input X.csv [-o Y.csv] [--clamp]

Evaluates the model on the displacement series in column displacement_mm of X.csv (other
columns are ignored) and writes displacement_mm,force_N to Y.csv (or standard output).
A table model covers only its range: an input outside it is an error unless --clamp is given,
which clamps and reports how many inputs were clamped.
)";

const char* kInvertHelp = R"(usage: hystlab invert --table T.json --input F.csv [-o Y.csv]

Force control: for each requested force in column force_N of F.csv, the displacement that
produces it from the model's current memory state (bisection), then the model moves there.
Writes displacement_mm,force_N (the force reached). A force outside what the table can reach
from the current state is an error naming its line.
)";
}  // namespace

int run_eval(const Args& args) {
  if (print_help_if_asked(args, kEvalHelp)) return 0;
  const Options opt(args, {"table", "model", "params", "input", "output"}, {"clamp"});
  LoadedModel m = load_model(opt);
  const Csv csv = Csv::load(opt.require("input"));
  const std::vector<double> x = csv.column("displacement_mm");
  if (m.hi > m.lo && !opt.has("clamp")) {
    for (std::size_t k = 0; k < x.size(); ++k)
      if (x[k] < m.lo || x[k] > m.hi)
        throw CliError(opt.get("input") + ": line " + std::to_string(csv.line_of(k)) + ": displacement " + format_number(x[k]) +
                       " mm is outside the table's range " + format_number(m.lo) + ".." + format_number(m.hi) + " mm (--clamp clamps and counts)");
  }
  std::vector<double> f(x.size());
  m.model->evaluate(x, f);
  write_output(opt.get("output"), to_csv({"displacement_mm", "force_N"}, {x, f}));
  if (const auto sat = m.model->saturation_count())
    std::cerr << "hystlab: " << sat << " of " << x.size() << " inputs were outside " << format_number(m.lo) << ".." << format_number(m.hi)
              << " mm and were clamped\n";
  return 0;
}

int run_invert(const Args& args) {
  if (print_help_if_asked(args, kInvertHelp)) return 0;
  const Options opt(args, {"table", "input", "output"}, {});
  const std::string path = opt.require("table");
  models::PreisachModel model(read_table_file(path).table);
  const models::Grid& g = model.table().grid();
  const Csv csv = Csv::load(opt.require("input"));
  const std::vector<double> target = csv.column("force_N");
  std::vector<double> x(target.size()), f(target.size());
  for (std::size_t k = 0; k < target.size(); ++k) {
    const models::InverseResult r = models::invert(model, target[k], g.lo, g.hi, 1e-9 * (g.hi - g.lo));
    if (r.error)
      throw CliError(opt.get("input") + ": line " + std::to_string(csv.line_of(k)) + ": force " + format_number(target[k]) +
                     " N cannot be reached from the current state (reachable " + format_number(model.peek(g.lo)) + ".." + format_number(model.peek(g.hi)) +
                     " N)");
    x[k] = r.displacement;
    f[k] = model.step(r.displacement);
  }
  write_output(opt.get("output"), to_csv({"displacement_mm", "force_N"}, {x, f}));
  return 0;
}

}  // namespace hystlab::cli
