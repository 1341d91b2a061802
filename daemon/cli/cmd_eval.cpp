// hystlab eval / invert: drive a model with a series from a CSV file.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/inverse.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/thermal_table.hpp"

namespace hystlab::cli {

namespace {
const char* kEvalHelp = R"(usage: hystlab eval (--table T.json | --model simplified [--params P.json]) --input X.csv [-o Y.csv] [--clamp]
       hystlab eval --model simplified [--params P.json] --temperature T --input X.csv [-o Y.csv]
       hystlab eval --table T1.json,T2.json,... [--identified-at T1,T2,...] (--temperature T | a temperature_C column)
                    --input X.csv [-o Y.csv] [--clamp]

Evaluates the model on the displacement series in column displacement_mm of X.csv (other
columns are ignored) and writes displacement_mm,force_N to Y.csv (or standard output).
A table model covers only its range: an input outside it is an error unless --clamp is given,
which clamps and reports how many inputs were clamped.

With temperature as an input: the simplified model at --temperature T (°C; its transformation
forces move by C per °C); or tables identified at several temperatures of one specimen, on one
grid, comma-separated, joined into a temperature-aware Preisach model (blended linearly between
the two identified temperatures around T, again when T moves 0.01 K; docs/
MODELS_IMPLEMENTATION.md "Temperature"), at
--temperature T or at each line's temperature_C in X.csv (then written as a third column). A
temperature outside the identified ones is an error unless --clamp is given. Without
--identified-at, each table's own provenance.temperature_C is taken (`hystlab identify --model
simplified` writes the parameters' T_degC there).
)";

const char* kInvertHelp = R"(usage: hystlab invert --table T.json --input F.csv [-o Y.csv]

Force control: for each requested force in column force_N of F.csv, the displacement that
produces it from the model's current memory state (bisection), then the model moves there.
Writes displacement_mm,force_N (the force reached). A force outside what the table can reach
from the current state is an error naming its line.
)";
}  // namespace

namespace {
// Tables at several temperatures, as one temperature-aware Preisach model.
int run_thermal_eval(const Options& opt) {
  if (opt.has("model") || opt.has("params")) throw CliError("--identified-at joins tables: give --table T1.json,T2.json,... without --model or --params");
  std::vector<std::string> paths;
  std::stringstream list(opt.require("table"));
  for (std::string p; std::getline(list, p, ',');) {
    const auto b = p.find_first_not_of(" \t"), e = p.find_last_not_of(" \t");
    paths.push_back(b == std::string::npos ? "" : p.substr(b, e - b + 1));
  }
  // The temperatures: --identified-at, or each table's own (provenance.temperature_C, which
  // `hystlab identify --model simplified` writes), the tables then taken in their order.
  std::vector<double> temps = opt.numbers("identified-at");
  if (opt.has("identified-at") && paths.size() != temps.size())
    throw CliError("--identified-at: " + std::to_string(temps.size()) + " temperatures for " + std::to_string(paths.size()) + " tables in --table");
  std::vector<std::pair<double, models::EverettTable>> read;
  for (std::size_t k = 0; k < paths.size(); ++k) {
    models::TableDocument doc = read_table_file(paths[k]);
    if (!opt.has("identified-at") && !doc.provenance.temperature_C)
      throw CliError(paths[k] + ": the table does not say the temperature it was identified at (provenance.temperature_C): give --identified-at T1,T2,...");
    read.emplace_back(opt.has("identified-at") ? temps[k] : *doc.provenance.temperature_C, std::move(doc.table));
  }
  if (!opt.has("identified-at")) std::stable_sort(read.begin(), read.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  temps.clear();
  std::vector<models::EverettTable> tables;
  for (auto& [T, t] : read) temps.push_back(T), tables.push_back(std::move(t));
  models::ThermalTable tt;
  try {
    tt = models::make_thermal_table(temps, std::move(tables));
  } catch (const std::invalid_argument& e) {
    throw CliError(std::string("--table/--identified-at: ") + e.what());
  }
  const double lo = tt.tables[0]->grid().lo, hi = tt.tables[0]->grid().hi, tlo = temps.front(), thi = temps.back();
  const bool clamp = opt.has("clamp");
  const Csv csv = Csv::load(opt.require("input"));
  const std::vector<double> x = csv.column("displacement_mm");
  std::vector<double> temp;
  if (opt.has("temperature")) {
    if (csv.has_column("temperature_C")) throw CliError("--temperature: " + opt.get("input") + " has a temperature_C column too; give one or the other");
    temp.assign(x.size(), opt.number("temperature", 0));
  } else if (csv.has_column("temperature_C")) {
    temp = csv.column("temperature_C");
  } else {
    throw CliError("tables at several temperatures need --temperature T or a temperature_C column in " + opt.get("input"));
  }
  for (std::size_t k = 0; k < x.size() && !clamp; ++k) {
    const std::string where = opt.has("temperature") ? "--temperature" : opt.get("input") + ": line " + std::to_string(csv.line_of(k));
    if (!(temp[k] >= tlo && temp[k] <= thi))
      throw CliError(where + ": temperature " + format_number(temp[k]) + " °C is outside the identified " + format_number(tlo) + ".." + format_number(thi) +
                     " °C (--clamp clamps and counts)");
    if (x[k] < lo || x[k] > hi)
      throw CliError(opt.get("input") + ": line " + std::to_string(csv.line_of(k)) + ": displacement " + format_number(x[k]) +
                     " mm is outside the tables' range " + format_number(lo) + ".." + format_number(hi) + " mm (--clamp clamps and counts)");
  }
  models::ThermalPreisachModel model(tt, temp.at(0));  // the CSV's numbers are finite (Csv::column)
  std::vector<double> f(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) {
    model.set_temperature(temp[k]);
    temp[k] = model.temperature();  // as used: clamped with --clamp
    f[k] = model.step(x[k]);
  }
  write_output(opt.get("output"),
               opt.has("temperature") ? to_csv({"displacement_mm", "force_N"}, {x, f}) : to_csv({"displacement_mm", "temperature_C", "force_N"}, {x, temp, f}));
  if (model.saturation_count() || model.temperature_saturation_count())
    std::cerr << "hystlab: " << model.saturation_count() << " displacement(s) outside " << format_number(lo) << ".." << format_number(hi) << " mm and "
              << model.temperature_saturation_count() << " temperature(s) outside " << format_number(tlo) << ".." << format_number(thi) << " °C were clamped\n";
  return 0;
}
}  // namespace

int run_eval(const Args& args) {
  if (print_help_if_asked(args, kEvalHelp)) return 0;
  const Options opt(args, {"table", "model", "params", "input", "output", "temperature", "identified-at"}, {"clamp"});
  if (opt.has("identified-at") || opt.get("table").find(',') != std::string::npos) return run_thermal_eval(opt);
  if (opt.has("temperature") && opt.has("table"))
    throw CliError("--temperature: a table is identified at one temperature; give the tables of several with --table T1.json,T2.json --identified-at T1,T2");
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
