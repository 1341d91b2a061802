#pragma once
// A PostgreSQL result's values as the lab's readers take them (lab_reads.cpp, pg_reads.cpp).
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "hystlab/db/pg.hpp"

namespace hystlab::db {
inline std::string pg_opt(const PgResult& r, int row, int col) { return r.is_null(row, col) ? std::string() : r.text(row, col); }
inline std::int64_t pg_opt_int(const PgResult& r, int row, int col) { return r.is_null(row, col) ? 0 : r.integer(row, col); }
// float8's text is the shortest that reads back to the same double (PostgreSQL 12 on): exact.
inline double pg_num(const PgResult& r, int row, int col) { return r.is_null(row, col) ? std::nan("") : std::strtod(r.text(row, col).c_str(), nullptr); }
}  // namespace hystlab::db
