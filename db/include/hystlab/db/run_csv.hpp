#pragma once
// A run's samples as CSV (docs/FORMATS.md, "Runs as CSV"): the one layout of `hystlab runs export`
// and GET /api/runs/ID/samples.csv, written here for both, so the two give the same bytes:
//
//   seq,t_s,<the rig kind's signals (signals.hpp), each name with its unit>,status
//
// one row per stored sample in seq order; numbers in the shortest form that reads back to the
// same double (models/text_forms.hpp), seq and status as integers. Rows are appended a window of
// seq at a time: a caller streams a run of any length in bounded memory.
#include <cstdint>
#include <string>

namespace hystlab::db {

class ReadSource;
struct SampleRow;
struct ShakerRow;

// Where a run's samples are: a load frame's table, a shaker's, or none.
enum class RunSamples { none, frame, shaker };
[[nodiscard]] RunSamples run_samples(ReadSource& store, std::int64_t run);

// The header line (with its '\n') of a load frame's run, or of a shaker's.
[[nodiscard]] std::string run_csv_header(bool shaker);

// One row, with its '\n'.
void append_csv_row(std::string& out, const SampleRow& r);
void append_csv_row(std::string& out, const ShakerRow& r);

// The rows of samples seq0..seq1 (inclusive) of the run appended to out; returns how many. A
// window of kRunCsvWindow seq keeps a streamed export's buffer near a megabyte.
inline constexpr std::int64_t kRunCsvWindow = 8192;
std::int64_t append_csv_rows(ReadSource& store, std::int64_t run, bool shaker, std::int64_t seq0, std::int64_t seq1, std::string& out);

// The last seq of the run's samples (-1: none).
[[nodiscard]] std::int64_t last_seq(ReadSource& store, std::int64_t run, bool shaker);

}  // namespace hystlab::db
