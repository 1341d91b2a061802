// hystlab: the command-line tool. Verbs in cmd_*.cpp; user errors exit 2 with one line.
#include <cstring>
#include <exception>
#include <iostream>
#include <string>
#include <string_view>

#include "cli_support.hpp"
#include "commands.hpp"
#include "hystlab/fmu/element_export.hpp"

namespace hystlab::cli {

bool print_help_if_asked(const Args& args, const char* text) {
  for (const auto& a : args)
    if (a == "--help" || a == "-h") {
      std::cout << text;
      return true;
    }
  return false;
}

namespace {
// Every verb and sub-command, and every export format ({formats}: fmu::kExportFormatList, the
// list the exports accept).
const char* kUsage = R"(hystlab: identify and use hysteresis models (Preisach/Everett tables, simplified SMA model)

usage: hystlab <verb> [options]     (hystlab <verb> --help for each; hystlab --version)

On files:
  eval       run a table or the simplified model on a displacement series
  identify   a table from a model (virtual FOT campaign) or from measured FOT nodes
  fit        a table from any displacement/force record (least squares, prior decided by held-out data)
  design     where a next FOT campaign's rows should go on a specimen already identified
  calibrate  simplified-model parameters from one measured loop
  invert     displacements that produce requested forces (force control)
  check      wiping-out and congruency of a record, as numbers
  compare    accuracy of a table or model against a record (or of a stored table on a stored run)
  loops      the material figures of every closed cycle of a record (energy, damping, plateaus, ...)
  demo       the paper's §3.3 study on Table 1, with a report and plots
  simulate sdof
             the base-excited isolator (sdof): time histories, transmissibility sweeps
  export --format {formats}
             a table or parameters as JSON, CSV, MATLAB/Octave script, C header or FMI 2.0 FMU

With hystlabd (commands over its HTTP API; records read from its database file):
  campaign submit|preview|pause|resume|abort|estop|record
             submit or preview a plan; command a campaign of the running daemon; record its specimen and notes
  campaign list|show
             the campaigns, from the daemon's database file
  rig estop|reset|recover NAME
             e-stop, reset or recover one of the running daemon's rigs
  tables list|export --format {formats}
             list and export the tables the daemon identified
  runs export --format csv|h5
             a run's samples as CSV or HDF5, or a whole campaign as HDF5 (--campaign ID)
  report ID -o FILE.html|FILE.pdf
             a campaign's report (HTML, or PDF through Chromium) from the running daemon

A lab of many rigs (the lab database every daemon replicates into: --pg URL):
  lab campaigns|tables|show|compare
             every daemon's campaigns and tables; one campaign; one specimen's tables ranked across rigs
  runs export RUN_ID --pg URL --daemon NAME
             a run's samples from the lab, as CSV (the same bytes as from the daemon's file)
)";

// kUsage with the export formats filled in.
std::string usage() {
  std::string formats, text = kUsage;
  for (const std::string_view f : fmu::kExportFormatList) formats += (formats.empty() ? "" : "|") + std::string(f);
  for (std::size_t at = text.find("{formats}"); at != std::string::npos; at = text.find("{formats}", at)) text.replace(at, 9, formats);
  return text;
}

int dispatch(const std::string& verb, const Args& args) {
  if (verb == "eval") return run_eval(args);
  if (verb == "identify") return run_identify(args);
  if (verb == "fit") return run_fit(args);
  if (verb == "design") return run_design(args);
  if (verb == "calibrate") return run_calibrate(args);
  if (verb == "invert") return run_invert(args);
  if (verb == "check") return run_check(args);
  if (verb == "compare") return run_compare(args);
  if (verb == "loops") return run_loops(args);
  if (verb == "demo") return run_demo(args);
  if (verb == "campaign") return run_campaign_cmd(args);
  if (verb == "rig") return run_rig_cmd(args);
  if (verb == "tables") return run_tables_cmd(args);
  if (verb == "runs") return run_runs_cmd(args);
  if (verb == "lab") return run_lab_cmd(args);
  if (verb == "simulate") return run_simulate(args);
  if (verb == "export") return run_export(args);
  if (verb == "report") return run_report(args);
  throw CliError("unknown verb '" + verb + "' (hystlab --help lists them)");
}
}  // namespace
}  // namespace hystlab::cli

int main(int argc, char** argv) {
  using namespace hystlab::cli;
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    std::cout << usage();
    return argc < 2 ? 2 : 0;
  }
  if (std::strcmp(argv[1], "--version") == 0) {
    std::cout << "hystlab " << HYSTLAB_VERSION << "\n";
    return 0;
  }
  const Args args(argv + 2, argv + argc);
  try {
    return dispatch(argv[1], args);
  } catch (const std::exception& e) {  // CliError, and the models' std::invalid_argument / FormatError
    std::cerr << "hystlab: error: " << e.what() << "\n";
    return 2;
  }
}
