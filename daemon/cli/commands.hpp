#pragma once
#include <optional>
#include <string>
#include <vector>

#include "hystlab/models/element.hpp"

namespace hystlab::cli {

using Args = std::vector<std::string>;

// Each verb returns the process exit code; user errors throw CliError.
int run_eval(const Args& args);
int run_identify(const Args& args);
int run_fit(const Args& args);
int run_design(const Args& args);
int run_calibrate(const Args& args);
int run_invert(const Args& args);
int run_check(const Args& args);
int run_compare(const Args& args);
int run_loops(const Args& args);
int run_demo(const Args& args);
int run_campaign_cmd(const Args& args);
int run_rig_cmd(const Args& args);
int run_report(const Args& args);
int run_tables_cmd(const Args& args);
int run_runs_cmd(const Args& args);
int run_lab_cmd(const Args& args);
int run_simulate(const Args& args);
int run_export(const Args& args);
// Writes a table or parameter document in an export format (hystlab export, tables export).
// kind: the one the user named (a document of the other kind is refused), or none.
void write_export(const std::string& document, const std::string& format, const std::string& name, const std::string& output,
                  std::optional<models::ElementKind> kind = {});

// True (and the help printed) when args ask for it.
bool print_help_if_asked(const Args& args, const char* text);

}  // namespace hystlab::cli
