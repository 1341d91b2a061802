// Runs and campaigns as HDF5: the file's layout (docs/FORMATS.md, "Runs as HDF5"). The samples
// are read a window of seq at a time and appended, so memory stays bounded whatever the run's length.
#include "hystlab/db/run_h5.hpp"

#include <nlohmann/json.hpp>

#include <malloc.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <vector>

#include "h5_file.hpp"
#include "h5_layout.hpp"
#include "hystlab/db/store.hpp"
#include "hystlab/domain/signals.hpp"
#include "hystlab/models/text_forms.hpp"

namespace hystlab::db {
namespace {
using h5::Handle;

std::string utc_now() { return models::iso8601_utc(std::time(nullptr)); }

// "force (N)" -> "N": the unit is the label's last parenthesis (signals.hpp names each signal once).
std::string unit_of(const char* label) {
  const std::string l = label;
  const auto open = l.rfind('('), close = l.rfind(')');
  return open == std::string::npos || close == std::string::npos || close < open ? std::string() : l.substr(open + 1, close - open - 1);
}

// Where a run's samples are: a load frame's table or a shaker's (none: no samples).
enum class RigKind { none, frame, shaker };
RigKind rig_kind_of(ReadSource& store, std::int64_t run) {
  if (store.max_seq(run) >= 0) return RigKind::frame;
  return store.max_shaker_seq(run) >= 0 ? RigKind::shaker : RigKind::none;
}

// One window of samples as columns, appended to the datasets and cleared.
struct SampleColumns {
  std::vector<std::int64_t> seq, status;
  std::vector<std::vector<double>> v;  // time_s, then the signals
  std::vector<h5::Column> out;         // seq, time_s, the signals, status
  void flush() {
    out.front().append(std::span<const std::int64_t>(seq));
    for (std::size_t k = 0; k < v.size(); ++k) out[k + 1].append(std::span<const double>(v[k]));
    out.back().append(std::span<const std::int64_t>(status));
    seq.clear(), status.clear();
    for (auto& c : v) c.clear();
  }
};

template <std::size_t N>
SampleColumns make_columns(hid_t group, const std::array<domain::SignalName, N>& signals, double wall_anchor, const H5ExportOptions& opt) {
  const auto chunk = static_cast<std::size_t>(opt.rows_per_read);
  SampleColumns c;
  c.v.resize(N + 1);
  c.out.emplace_back(group, "seq", h5::Column::Type::i64, chunk, opt.deflate_level);
  c.out.emplace_back(group, "time_s", h5::Column::Type::f64, chunk, opt.deflate_level);
  h5::attr_text(c.out.back().id(), "units", "s");
  h5::attr_text(c.out.back().id(), "label", "rig time (s)");
  h5::attr_double(c.out.back().id(), "wall_anchor_unix", wall_anchor);
  for (const domain::SignalName& s : signals) {
    c.out.emplace_back(group, s.name, h5::Column::Type::f64, chunk, opt.deflate_level);
    h5::attr_text(c.out.back().id(), "units", unit_of(s.label));
    h5::attr_text(c.out.back().id(), "label", s.label);
  }
  c.out.emplace_back(group, "status", h5::Column::Type::i64, chunk, opt.deflate_level);
  return c;
}

// Every sample of the run, in seq order; returns how many.
std::int64_t write_samples(ReadSource& store, hid_t group, const RunInfo& run, RigKind kind, const H5ExportOptions& opt) {
  const std::int64_t last = kind == RigKind::frame ? store.max_seq(run.id) : store.max_shaker_seq(run.id), step = opt.rows_per_read;
  SampleColumns c = kind == RigKind::frame ? make_columns(group, domain::kFrameSignals, run.wall_anchor_unix, opt)
                                           : make_columns(group, domain::kShakerSignals, run.wall_anchor_unix, opt);
  std::int64_t n = 0;
  for (std::int64_t s0 = 0; s0 <= last; s0 += step) {
    if (kind == RigKind::frame) {
      store.for_each_sample(run.id, s0, s0 + step - 1, [&c](const SampleRow& r) {
        c.seq.push_back(r.seq), c.status.push_back(r.status), c.v[0].push_back(r.t);
        c.v[1].push_back(r.cmd), c.v[2].push_back(r.disp), c.v[3].push_back(r.force);
      });
    } else {
      store.for_each_shaker_sample(run.id, s0, s0 + step - 1, [&c](const ShakerRow& r) {
        c.seq.push_back(r.seq), c.status.push_back(r.status), c.v[0].push_back(r.t);
        const auto v = domain::values(r.v);
        for (std::size_t k = 0; k < v.size(); ++k) c.v[k + 1].push_back(v[k]);
      });
    }
    n += static_cast<std::int64_t>(c.seq.size());
    c.flush();
  }
  return n;
}

std::int64_t write_run(ReadSource& store, hid_t runs, const RunInfo& run, RigKind kind, const H5ExportOptions& opt) {
  const Handle g = h5::create_group(runs, "run_" + std::to_string(run.id));
  h5::attr_int(g.get(), "id", run.id);
  h5::attr_int(g.get(), "campaign", run.campaign);
  h5::attr_text(g.get(), "role", run.role);
  h5::attr_text(g.get(), "state", run.state);
  h5::attr_text(g.get(), "started_at", run.started_at);
  h5::attr_text(g.get(), "ended_at", run.ended_at);
  h5::attr_double(g.get(), "wall_anchor_unix", run.wall_anchor_unix);
  h5::attr_text(g.get(), "rig_kind", kind == RigKind::frame ? "load frame" : "shaker");
  const std::int64_t n = write_samples(store, g.get(), run, kind, opt);
  h5::attr_int(g.get(), "samples", n);
  return n;
}

void write_root(hid_t file, const char* scope, std::int64_t campaign) {
  h5::attr_text(file, "format", kRunH5Format);
  h5::attr_int(file, "format_version", kRunH5Version);
  h5::attr_text(file, "software", "hystlab");
  h5::attr_text(file, "software_version", HYSTLAB_VERSION);
  h5::attr_text(file, "created", utc_now());
  h5::attr_text(file, "scope", scope);
  h5::attr_int(file, "campaign", campaign);
}

// Creates the file, lets `body` fill it, closes it (a failed close is a failed write); on any
// failure the file is removed, so no half file is left.
template <class F>
H5ExportStats write_file(const std::string& path, F body) {
  h5::silence_error_stack();
  bool created = false;
  try {
    Handle f = h5::create_file(path);
    created = true;
    const H5ExportStats stats = body(f.get());
    f.close("finish writing '" + path + "'");
    return stats;
  } catch (...) {
    if (created) std::remove(path.c_str());
    throw;
  }
}

H5ExportStats write_runs(ReadSource& store, hid_t file, const char* scope, std::int64_t campaign, const std::vector<std::pair<RunInfo, RigKind>>& runs,
                         const H5ExportOptions& opt) {
  write_root(file, scope, campaign);
  H5ExportStats stats;
  stats.tables = h5_layout::write_campaign(store, file, campaign, opt.deflate_level);
  const Handle g = h5::create_group(file, "runs");
  for (const auto& [run, kind] : runs) {
    stats.samples += write_run(store, g.get(), run, kind, opt);
    ++stats.runs;
  }
  return stats;
}

void check_options(const H5ExportOptions& opt) {
  if (opt.rows_per_read < 1 || opt.rows_per_read > (std::int64_t{1} << 24)) throw H5ExportError(H5ExportError::Kind::write, "rows_per_read must be in 1..2^24");
}
}  // namespace

H5ExportStats export_run_h5(ReadSource& store, std::int64_t run_id, const std::string& path, const H5ExportOptions& opt) {
  check_options(opt);
  const auto run = store.run(run_id);
  if (!run) throw H5ExportError(H5ExportError::Kind::not_found, "no run " + std::to_string(run_id));
  const RigKind kind = rig_kind_of(store, run_id);
  if (kind == RigKind::none) throw H5ExportError(H5ExportError::Kind::no_samples, "no samples for run " + std::to_string(run_id));
  return write_file(path, [&](hid_t f) { return write_runs(store, f, "run", run->campaign, {{*run, kind}}, opt); });
}

H5ExportStats export_campaign_h5(ReadSource& store, std::int64_t campaign_id, const std::string& path, const H5ExportOptions& opt) {
  check_options(opt);
  if (!store.campaign(campaign_id)) throw H5ExportError(H5ExportError::Kind::not_found, "no campaign " + std::to_string(campaign_id));
  std::vector<std::pair<RunInfo, RigKind>> runs;
  for (const RunInfo& r : store.runs(campaign_id))
    if (const RigKind k = rig_kind_of(store, r.id); k != RigKind::none) runs.emplace_back(r, k);
  if (runs.empty()) throw H5ExportError(H5ExportError::Kind::no_samples, "no samples in any run of campaign " + std::to_string(campaign_id));
  return write_file(path, [&](hid_t f) { return write_runs(store, f, "campaign", campaign_id, runs, opt); });
}

void release_export_memory() noexcept {
  (void)H5garbage_collect();
  (void)malloc_trim(0);
}

}  // namespace hystlab::db
