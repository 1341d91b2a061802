#pragma once
// Runs and campaigns as HDF5 files (docs/FORMATS.md, "Runs as HDF5"): every sample of a run, one
// dataset per signal, with its campaign's plan, rig, events, FOT nodes and tables. Samples are
// read from the store a window at a time and appended, so a run of any length is written in
// bounded memory. Only the CLI and the web link this (hystlab::h5): the daemon's core needs no HDF5.
#include <cstdint>
#include <stdexcept>
#include <string>

namespace hystlab::db {

class ReadSource;

inline constexpr const char* kRunH5Format = "hystlab-run-h5";
inline constexpr int kRunH5Version = 1;

// One error for every failure, with what failed in words; kind tells the API which status to answer.
struct H5ExportError : std::runtime_error {
  enum class Kind { not_found, no_samples, write };
  H5ExportError(Kind k, const std::string& what) : std::runtime_error(what), kind(k) {}
  Kind kind;
};

struct H5ExportOptions {
  std::int64_t rows_per_read = 65536;  // samples read from the store and appended at a time (also the chunk length)
  int deflate_level = 1;               // 0-9; shuffle before deflate makes doubles compress (level 4: 1 % smaller, 9 % slower)
};

struct H5ExportStats {
  std::int64_t runs = 0, samples = 0, tables = 0;
};

// Writes run `run_id` and its campaign's records to `path` (created or truncated). Throws
// H5ExportError: no such run, a run without samples, or a write that failed; the file is then removed.
H5ExportStats export_run_h5(ReadSource& store, std::int64_t run_id, const std::string& path, const H5ExportOptions& opt = {});
// The same for every run of a campaign that has samples (at least one must).
H5ExportStats export_campaign_h5(ReadSource& store, std::int64_t campaign_id, const std::string& path, const H5ExportOptions& opt = {});

// What an export took, given back: the HDF5 library's free lists and the heap's freed pages
// (a long-running daemon kept about 2.2 MB more after each export without it).
void release_export_memory() noexcept;

}  // namespace hystlab::db
