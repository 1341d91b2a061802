// hystlab runs export: a run's samples as CSV, streamed to the output as they are read (a 10^7-
// sample run never sits in memory), or a run or a whole campaign as HDF5 (docs/FORMATS.md).
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iostream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "hystlab/db/lab_reads.hpp"
#include "hystlab/db/pg_reads.hpp"
#include "hystlab/db/run_csv.hpp"
#include "hystlab/db/run_h5.hpp"
#include "hystlab/db/store.hpp"
#include "lab_access.hpp"

namespace hystlab::cli {
namespace {
const char* kRunsUsage = R"(usage: hystlab runs export RUN_ID [--format csv|h5] [-o FILE] [--db hystlab.db]
       hystlab runs export --campaign ID --format h5 -o FILE [--db hystlab.db]
       hystlab runs export RUN_ID --pg URL --daemon NAME [--lab NAME] [--format csv|h5] [-o FILE] [--pg-password-file FILE]
       hystlab runs export --campaign ID --pg URL --daemon NAME [--lab NAME] --format h5 -o FILE

csv (the default) writes the run's samples, to FILE or stdout, as GET /api/runs/ID/samples.csv
does (docs/FORMATS.md, "Runs as CSV"): a load frame's seq,t_s,command_mm,displacement_mm,force_N,
status; a shaker's seq,t_s,drive_frequency_hz,drive_amplitude_mm,base_displacement_mm,
mass_displacement_mm,base_accel_m_s2,mass_accel_m_s2,status. Numbers are in the shortest form that
reads back exactly.

h5 writes an HDF5 file (docs/FORMATS.md, "Runs as HDF5"): the run's samples, one dataset per
signal with its units, and its campaign's plan, rig, events, FOT nodes and tables. With
--campaign, every run of that campaign. HDF5 is binary: -o must name a file.
A failed export leaves no file behind.

With --pg, the run is read from the lab database (docs/LAB.md) that daemon NAME replicates into
(RUN_ID: its id on that daemon, as hystlab lab show lists it): the same CSV, byte for byte, and
the same HDF5 layout as from that daemon's file, of what is replicated so far.
)";

std::int64_t whole_number(const std::string& text, const std::string& what) {
  std::int64_t v = 0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (r.ec != std::errc() || r.ptr != text.data() + text.size() || v <= 0) throw CliError(what + " must be a positive whole number, got '" + text + "'");
  return v;
}

// The run's CSV (db/run_csv.hpp: the API's layout and bytes), written a window of samples at a
// time: bounded memory at any length.
void write_csv_rows(db::ReadSource& store, std::int64_t id, bool shaker, std::FILE* f, const std::string& name) {
  std::string buf = db::run_csv_header(shaker);
  const std::int64_t last = db::last_seq(store, id, shaker);
  for (std::int64_t seq0 = 0; seq0 <= last; seq0 += db::kRunCsvWindow) {
    (void)db::append_csv_rows(store, id, shaker, seq0, seq0 + db::kRunCsvWindow - 1, buf);
    if (std::fwrite(buf.data(), 1, buf.size(), f) != buf.size()) throw CliError("cannot write " + name + ": " + std::strerror(errno));
    buf.clear();
  }
}

// To stdout, or to FILE.tmp renamed to FILE once complete (a failure leaves no half file).
// write(f, name): the rows to f, name the output's for its errors.
void write_csv_output(const std::string& path, const std::function<void(std::FILE*, const std::string&)>& write) {
  if (path.empty() || path == "-") {
    write(stdout, "to stdout");
    if (std::fflush(stdout) != 0) throw CliError(std::string("cannot write to stdout: ") + std::strerror(errno));
    return;
  }
  const std::string tmp = path + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr) throw CliError("-o: cannot write '" + path + "': " + std::strerror(errno));
  try {
    write(f, "'" + path + "'");
  } catch (...) {
    std::fclose(f);
    std::remove(tmp.c_str());
    throw;
  }
  const bool closed = std::fclose(f) == 0;
  if (!closed || std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    std::remove(tmp.c_str());
    throw CliError("-o: cannot write '" + path + "': " + why);
  }
}

void export_csv(db::ReadSource& store, std::int64_t id, const std::string& path) {
  const db::RunSamples where = db::run_samples(store, id);
  if (where == db::RunSamples::none) throw CliError("no samples for run " + std::to_string(id));
  const bool shaker = where == db::RunSamples::shaker;  // a shaker's run: its own columns
  write_csv_output(path, [&](std::FILE* f, const std::string& name) { write_csv_rows(store, id, shaker, f, name); });
}

// HDF5 beside the target, then renamed: the export removes its own file when it fails.
void export_h5(db::ReadSource& store, std::int64_t id, bool campaign, const std::string& path) {
  if (path.empty() || path == "-") throw CliError("-o: HDF5 is a binary file: give its name (-o run.h5); it is not written to stdout");
  const std::string tmp = path + ".tmp";
  try {
    const db::H5ExportStats s = campaign ? db::export_campaign_h5(store, id, tmp) : db::export_run_h5(store, id, tmp);
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
      const std::string why = std::strerror(errno);
      std::remove(tmp.c_str());
      throw CliError("-o: cannot write '" + path + "': " + why);
    }
    std::cerr << "wrote " << path << ": " << s.runs << " run(s), " << s.samples << " samples, " << s.tables << " table(s)\n";
  } catch (const db::H5ExportError& e) {
    if (e.kind != db::H5ExportError::Kind::write) throw CliError(e.what());
    throw CliError("-o: cannot write '" + path + "' (" + e.what() + ")");
  }
}

// From the lab database: the daemon's rows there as a ReadSource (db/pg_reads.hpp), through the
// same writers as from its file: the same CSV bytes and HDF5 layout, of what is replicated so far.
int export_from_lab(const Options& opt, const std::string& format, bool campaign, std::int64_t id) {
  const auto pg = connect_lab(opt);
  db::LabReads lab(*pg);
  try {
    const db::LabDaemon daemon = lab_daemon(lab, opt.require("daemon"), opt.get("lab"));
    db::PgReads store(*pg, daemon.id);
    const std::string where = " on daemon '" + daemon.name + "' in the lab database";
    if (campaign && !store.campaign(id)) throw CliError("no campaign " + std::to_string(id) + where);
    if (!campaign) {
      const auto run = store.run(id);
      if (!run) throw CliError("no samples for run " + std::to_string(id) + ": there is no run " + std::to_string(id) + where);
      if (run->samples == 0) throw CliError("no samples for run " + std::to_string(id) + where + " (none replicated yet)");
    }
    if (format == "csv")
      export_csv(store, id, opt.get("output"));
    else
      export_h5(store, id, campaign, opt.get("output"));
  } catch (const db::PgError& e) {
    throw CliError("the lab database: " + one_line(e.what()));
  }
  return 0;
}
}  // namespace

int run_runs_cmd(const Args& args) {
  if (print_help_if_asked(args, kRunsUsage)) return 0;
  if (args.empty() || args[0] != "export") {
    std::cout << kRunsUsage;
    return 2;
  }
  const bool positional = args.size() > 1 && !args[1].starts_with("-");
  const Options opt(Args(args.begin() + (positional ? 2 : 1), args.end()), {"db", "output", "format", "campaign", "pg", "pg-password-file", "daemon", "lab"},
                    {});
  const std::string format = opt.get("format", "csv");
  if (format != "csv" && format != "h5") throw CliError("--format: '" + format + "' is not csv or h5");
  const bool lab = opt.has("pg") || opt.has("daemon") || opt.has("lab") || opt.has("pg-password-file");
  if (lab && opt.has("db")) throw CliError("--db and --pg name two sources: give one (the daemon's file, or the lab database)");
  if (positional == opt.has("campaign")) throw CliError("give one of RUN_ID or --campaign ID (see --help)");
  if (opt.has("campaign") && format != "h5") throw CliError("--campaign: a whole campaign is exported as HDF5 only (--format h5)");
  const std::int64_t id = positional ? whole_number(args[1], "RUN_ID") : whole_number(opt.get("campaign"), "--campaign");
  if (lab) {
    if (!opt.has("daemon")) throw CliError("--pg: give --daemon NAME, the daemon whose run it is (hystlab lab campaigns lists them)");
    return export_from_lab(opt, format, !positional, id);
  }
  db::Store store = open_store(opt);
  if (positional && !store.run(id)) throw CliError("no samples for run " + std::to_string(id) + ": there is no run " + std::to_string(id));
  if (format == "csv")
    export_csv(store, id, opt.get("output"));
  else
    export_h5(store, id, !positional, opt.get("output"));
  return 0;
}

}  // namespace hystlab::cli
