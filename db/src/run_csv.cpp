#include "hystlab/db/run_csv.hpp"

#include "hystlab/db/store.hpp"
#include "hystlab/domain/signals.hpp"
#include "hystlab/models/text_forms.hpp"

namespace hystlab::db {

RunSamples run_samples(ReadSource& store, std::int64_t run) {
  if (store.max_seq(run) >= 0) return RunSamples::frame;
  return store.max_shaker_seq(run) >= 0 ? RunSamples::shaker : RunSamples::none;
}

std::string run_csv_header(bool shaker) { return shaker ? domain::csv_header(domain::kShakerSignals) : domain::csv_header(domain::kFrameSignals); }

namespace {
void number(std::string& out, double v) {
  models::append_exact(out, v);
  out.push_back(',');
}
}  // namespace

void append_csv_row(std::string& out, const SampleRow& r) {
  out += std::to_string(r.seq);
  out.push_back(',');
  for (const double v : {r.t, r.cmd, r.disp, r.force}) number(out, v);
  out += std::to_string(r.status);
  out.push_back('\n');
}

void append_csv_row(std::string& out, const ShakerRow& r) {
  out += std::to_string(r.seq);
  out.push_back(',');
  number(out, r.t);
  for (const double v : domain::values(r.v)) number(out, v);
  out += std::to_string(r.status);
  out.push_back('\n');
}

std::int64_t append_csv_rows(ReadSource& store, std::int64_t run, bool shaker, std::int64_t seq0, std::int64_t seq1, std::string& out) {
  std::int64_t rows = 0;
  if (shaker)
    store.for_each_shaker_sample(run, seq0, seq1, [&](const ShakerRow& r) { append_csv_row(out, r), ++rows; });
  else
    store.for_each_sample(run, seq0, seq1, [&](const SampleRow& r) { append_csv_row(out, r), ++rows; });
  return rows;
}

std::int64_t last_seq(ReadSource& store, std::int64_t run, bool shaker) { return shaker ? store.max_shaker_seq(run) : store.max_seq(run); }

}  // namespace hystlab::db
