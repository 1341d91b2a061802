// hystlab: the command-line tool. Verbs in cmd_*.cpp; user errors exit 2 with one line.
#include <cstring>
#include <exception>
#include <iostream>

#include "cli_support.hpp"
#include "commands.hpp"

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
const char* kUsage = R"(hystlab: identify and use hysteresis models (Preisach/Everett tables, simplified SMA model)

usage: hystlab <verb> [options]     (hystlab <verb> --help for each)

  eval       run a table or the simplified model on a displacement series
  identify   a table from a model (virtual FOT campaign) or from measured FOT nodes
  fit        a table from any displacement/force record (least squares, prior decided by held-out data)
  calibrate  simplified-model parameters from one measured loop
  invert     displacements that produce requested forces (force control)
  check      wiping-out and congruency of a record, as numbers
  compare    accuracy of a table or model against a record
  loops      the material figures of every closed cycle of a record (energy, damping, plateaus, ...)
  demo       the paper's §3.3 study on Table 1, with a report and plots
  campaign   submit, preview, pause, resume, abort, estop campaigns of the running hystlabd
             (over its HTTP API); list and show them from its db file
  rig        estop, reset or recover one of the running hystlabd's rigs (over its HTTP API)
  tables     list and export the tables hystlabd identified
  runs       export a run's samples as CSV, or a run or campaign as HDF5
  simulate   the base-excited isolator (sdof): time histories, transmissibility sweeps
  export     a table or parameters as JSON, CSV, MATLAB/Octave, a C header or an FMU
  report     a campaign's report (HTML, or PDF through Chromium) from the running hystlabd
)";

int dispatch(const std::string& verb, const Args& args) {
  if (verb == "eval") return run_eval(args);
  if (verb == "identify") return run_identify(args);
  if (verb == "fit") return run_fit(args);
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
    std::cout << kUsage;
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
