#pragma once
// The parts of a run's HDF5 file besides the samples (docs/FORMATS.md, "Runs as HDF5"): the
// campaign with its plan and rig, its events, FOT nodes and tables.
#include <hdf5.h>

#include <cstdint>

namespace hystlab::db {
class ReadSource;
}

namespace hystlab::db::h5_layout {

// /campaign, /events, /fot_nodes and /tables of the campaign; returns how many tables.
std::int64_t write_campaign(ReadSource& store, hid_t file, std::int64_t campaign, int deflate_level);
// /tables/table_<id>: each table's document as stored and as numbers, its provenance and scores.
std::int64_t write_tables(ReadSource& store, hid_t file, std::int64_t campaign, int deflate_level);

}  // namespace hystlab::db::h5_layout
