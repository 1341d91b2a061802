// hystlab export: a table or a parameter set for other tools (JSON, CSV, MATLAB/Octave, C).
#include <iostream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/table_export.hpp"

namespace hystlab::cli {
namespace {
const char* kExportHelp = R"(usage: hystlab export (--table T.json | --params P.json) --format json|csv|m|h [--name NAME] [-o OUT]

Writes a table or simplified-model parameters for other tools (docs/FORMATS.md):
  json  the canonical, versioned document (re-written, validated)
  csv   a table's nodes i,j,alpha_mm,beta_mm,F_N after # header lines; parameters as name,value,unit
  m     a MATLAB/Octave script: T (the table) with f = hystlab_eval(T, x), or P (the parameters)
  h     a C header of static const values, prefixed by NAME (default hystlab_table / hystlab_params)
)";
}  // namespace

int run_export(const Args& args) {
  if (print_help_if_asked(args, kExportHelp)) return 0;
  const Options opt(args, {"table", "params", "format", "name", "output"}, {});
  if (opt.has("table") == opt.has("params")) throw CliError("give one of --table T.json or --params P.json");
  const std::string format = opt.require("format");
  if (format != "json" && format != "csv" && format != "m" && format != "h")
    throw CliError("--format: '" + format + "' is not json, csv, m or h");
  std::string out;
  if (opt.has("table")) {
    const models::TableDocument doc = models::table_from_json(read_file(opt.get("table")));
    if (format == "json") out = models::table_to_json(doc.table, doc.provenance).dump(2) + "\n";
    if (format == "csv") out = models::table_to_csv(doc.table, doc.provenance);
    if (format == "m") out = models::table_to_matlab(doc.table, doc.provenance);
    if (format == "h") out = models::table_to_c_header(doc.table, doc.provenance, opt.get("name", "hystlab_table"));
  } else {
    const models::SmaParameters p = models::params_from_json(read_file(opt.get("params")));
    if (format == "json") out = models::params_to_json(p, opt.get("params")).dump(2) + "\n";
    if (format == "csv") out = models::params_to_csv(p);
    if (format == "m") out = models::params_to_matlab(p);
    if (format == "h") out = models::params_to_c_header(p, opt.get("name", "hystlab_params"));
  }
  write_output(opt.get("output"), out);
  return 0;
}

}  // namespace hystlab::cli
