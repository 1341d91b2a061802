// hystlab runs export: a run's samples as CSV, streamed to the output as they are read (a 10^7-
// sample run never sits in memory), or a run or a whole campaign as HDF5 (docs/FORMATS.md).
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "cli_support.hpp"
#include "commands.hpp"
#include "hystlab/db/run_h5.hpp"
#include "hystlab/db/signals.hpp"
#include "hystlab/db/store.hpp"
#include "hystlab/models/text_forms.hpp"

namespace hystlab::cli {
namespace {
const char* kRunsUsage = R"(usage: hystlab runs export RUN_ID [--format csv|h5] [-o FILE] [--db hystlab.db]
       hystlab runs export --campaign ID --format h5 -o FILE [--db hystlab.db]

csv (the default) writes the run's samples, to FILE or stdout: a load frame's
time_s,command_mm,displacement_mm,force_N,status; a shaker's time_s,drive_frequency_hz,
drive_amplitude_mm,base_displacement_mm,mass_displacement_mm,base_accel_m_s2,mass_accel_m_s2,status.
Numbers are in the shortest form that reads back exactly.

h5 writes an HDF5 file (docs/FORMATS.md, "Runs as HDF5"): the run's samples, one dataset per
signal with its units, and its campaign's plan, rig, events, FOT nodes and tables. With
--campaign, every run of that campaign. HDF5 is binary: -o must name a file.
A failed export leaves no file behind.
)";

std::int64_t whole_number(const std::string& text, const std::string& what) {
  std::int64_t v = 0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (r.ec != std::errc() || r.ptr != text.data() + text.size() || v <= 0)
    throw CliError(what + " must be a positive whole number, got '" + text + "'");
  return v;
}

// The CSV's rows, appended to a buffer written out every MiB: bounded memory at any length.
class CsvStream {
 public:
  CsvStream(std::FILE* f, std::string name) : f_(f), name_(std::move(name)) { buf_.reserve(kFlushAt + 4096); }
  void text(const char* s) { buf_ += s; }
  void number(double v) { models::append_exact(buf_, v); }
  void integer(std::int64_t v) { buf_ += std::to_string(v); }
  void end_row() {
    buf_ += '\n';
    if (buf_.size() >= kFlushAt) flush();
  }
  void flush() {
    if (!buf_.empty() && std::fwrite(buf_.data(), 1, buf_.size(), f_) != buf_.size())
      throw CliError("cannot write " + name_ + ": " + std::strerror(errno));
    buf_.clear();
  }

 private:
  static constexpr std::size_t kFlushAt = 1U << 20;
  std::FILE* f_;
  std::string name_, buf_;
};

void write_csv_rows(db::Store& store, std::int64_t id, bool shaker, CsvStream& out) {
  out.text("time_s");
  if (shaker) {
    for (const db::SignalName& n : db::kShakerSignals) out.text(","), out.text(n.name);
    out.text(",status");
    out.end_row();
    store.for_each_shaker_sample(id, 0, std::int64_t{1} << 50, [&out](const db::ShakerRow& r) {
      out.number(r.t);
      for (const double v : r.v) out.text(","), out.number(v);
      out.text(","), out.integer(r.status), out.end_row();
    });
  } else {
    for (const db::SignalName& n : db::kFrameSignals) out.text(","), out.text(n.name);
    out.text(",status");
    out.end_row();
    store.for_each_sample(id, 0, std::int64_t{1} << 50, [&out](const db::SampleRow& r) {
      out.number(r.t), out.text(","), out.number(r.cmd), out.text(","), out.number(r.disp), out.text(",");
      out.number(r.force), out.text(","), out.integer(r.status), out.end_row();
    });
  }
  out.flush();
}

// To stdout, or to FILE.tmp renamed to FILE once complete (a failure leaves no half file).
void export_csv(db::Store& store, std::int64_t id, const std::string& path) {
  const bool shaker = store.max_seq(id) < 0 && store.max_shaker_seq(id) >= 0;  // a shaker's run: its own columns
  if (store.max_seq(id) < 0 && !shaker) throw CliError("no samples for run " + std::to_string(id));
  if (path.empty() || path == "-") {
    CsvStream out(stdout, "to stdout");
    write_csv_rows(store, id, shaker, out);
    if (std::fflush(stdout) != 0) throw CliError(std::string("cannot write to stdout: ") + std::strerror(errno));
    return;
  }
  const std::string tmp = path + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr) throw CliError("-o: cannot write '" + path + "': " + std::strerror(errno));
  try {
    CsvStream out(f, "'" + path + "'");
    write_csv_rows(store, id, shaker, out);
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

// HDF5 beside the target, then renamed: the export removes its own file when it fails.
void export_h5(db::Store& store, std::int64_t id, bool campaign, const std::string& path) {
  if (path.empty() || path == "-")
    throw CliError("-o: HDF5 is a binary file: give its name (-o run.h5); it is not written to stdout");
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
}  // namespace

int run_runs_cmd(const Args& args) {
  if (print_help_if_asked(args, kRunsUsage)) return 0;
  if (args.empty() || args[0] != "export") {
    std::cout << kRunsUsage;
    return 2;
  }
  const bool positional = args.size() > 1 && !args[1].starts_with("-");
  const Options opt(Args(args.begin() + (positional ? 2 : 1), args.end()), {"db", "output", "format", "campaign"}, {});
  const std::string format = opt.get("format", "csv");
  if (format != "csv" && format != "h5") throw CliError("--format: '" + format + "' is not csv or h5");
  if (positional == opt.has("campaign")) throw CliError("give one of RUN_ID or --campaign ID (see --help)");
  if (opt.has("campaign") && format != "h5") throw CliError("--campaign: a whole campaign is exported as HDF5 only (--format h5)");
  const std::int64_t id = positional ? whole_number(args[1], "RUN_ID") : whole_number(opt.get("campaign"), "--campaign");
  db::Store store = open_store(opt);
  if (positional && !store.run(id)) throw CliError("no samples for run " + std::to_string(id) + ": there is no run " + std::to_string(id));
  if (format == "csv") export_csv(store, id, opt.get("output"));
  else export_h5(store, id, !positional, opt.get("output"));
  return 0;
}

}  // namespace hystlab::cli
