// hystlab export: a table or a parameter set for other tools (JSON, CSV, MATLAB/Octave, C, FMU).
#include <iostream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "hystlab/fmu/element_export.hpp"

namespace hystlab::cli {
namespace {
const char* kExportHelp = R"(usage: hystlab export (--table T.json | --params P.json) --format json|csv|m|h|fmu [--name NAME] [-o OUT]

Writes a table or simplified-model parameters for other tools (docs/FORMATS.md):
  json  the canonical, versioned document (re-written, validated)
  csv   a table's nodes i,j,alpha_mm,beta_mm,F_N after # header lines; parameters as name,value,unit
  m     a MATLAB/Octave script: T (the table) with f = hystlab_eval(T, x), or P (the parameters)
  h     a C header of static const values, prefixed by NAME (default hystlab_table / hystlab_params)
  fmu   an FMI 2.0 co-simulation FMU (Linux x86-64) for Simulink, Dymola, OpenModelica, Python...:
        input x (mm), output F (N); NAME is its model name. Needs -o FILE.fmu
)";
}  // namespace

void write_export(const std::string& document, const std::string& format, const std::string& name, const std::string& output,
                  std::optional<models::ElementKind> kind) {
  if (!fmu::is_export_format(format)) throw CliError("--format: '" + format + "' is not " + std::string(fmu::kExportFormats));
  const fmu::ExportedFile f = fmu::export_element(document, format, name, now_iso8601(), kind);
  if (f.binary && (output.empty() || output == "-")) throw CliError("--format " + format + " writes a binary archive: give -o FILE." + format);
  write_output(output, f.bytes);
}

int run_export(const Args& args) {
  if (print_help_if_asked(args, kExportHelp)) return 0;
  const Options opt(args, {"table", "params", "format", "name", "output"}, {});
  if (opt.has("table") == opt.has("params")) throw CliError("give one of --table T.json or --params P.json");
  const std::string format = opt.require("format");
  if (!fmu::is_export_format(format)) throw CliError("--format: '" + format + "' is not " + std::string(fmu::kExportFormats));
  const bool table = opt.has("table");
  const std::string path = opt.get(table ? "table" : "params");
  // The document checked as its file first: a fault names the file (the export re-reads the text).
  if (table)
    (void)read_table_file(path);
  else
    (void)read_params_file(path);
  const std::string doc = read_file(path);
  write_export(doc, format, opt.get("name", table ? "hystlab_table" : "hystlab_params"), opt.get("output"),
               table ? models::ElementKind::Table : models::ElementKind::Params);
  return 0;
}

}  // namespace hystlab::cli
