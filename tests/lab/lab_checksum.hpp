#pragma once
// What the lab tests compare: row counts, and a checksum of every sample on either side.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "hystlab/db/pg.hpp"
#include "hystlab/db/sqlite.hpp"

namespace hystlab::lab_test {

// A checksum of every sample: FNV-1a over (run, seq, every value's bits, status), in key order.
struct Checksum {
  std::uint64_t h = 1469598103934665603ULL;
  std::int64_t rows = 0;
  void add(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t k = 0; k < n; ++k) h = (h ^ b[k]) * 1099511628211ULL;
  }
  void add_int(std::int64_t v) { add(&v, sizeof v); }
  void add_double(double v) { add(&v, sizeof v); }
};

inline Checksum lite_samples(db::Database& d) {
  Checksum c;
  db::Statement st(d, "SELECT run_id, seq, t, cmd, disp, force, status FROM samples ORDER BY run_id, seq");
  while (st.step()) {
    c.add_int(st.column_int(0)), c.add_int(st.column_int(1));
    for (int k = 2; k < 6; ++k) c.add_double(st.column_double(k));
    c.add_int(st.column_int(6));
    ++c.rows;
  }
  return c;
}

inline Checksum pg_samples(db::PgConnection& pg, int daemon) {
  Checksum c;
  const std::string id = std::to_string(daemon);
  const db::PgResult r =
      pg.query("SELECT run_id, seq, t, cmd, disp, force, status FROM hystlab.samples WHERE daemon_id = $1 ORDER BY run_id, seq", {id.c_str()});
  for (int row = 0; row < r.rows(); ++row) {
    c.add_int(r.integer(row, 0)), c.add_int(r.integer(row, 1));
    for (int k = 2; k < 6; ++k) c.add_double(std::strtod(r.text(row, k).c_str(), nullptr));
    c.add_int(r.integer(row, 6));
    ++c.rows;
  }
  return c;
}

inline std::int64_t lite_count(db::Database& d, const std::string& table) {
  db::Statement st(d, "SELECT count(*) FROM " + table);
  st.step();
  return st.column_int(0);
}
inline std::int64_t pg_count(db::PgConnection& pg, const std::string& table, int daemon) {
  const std::string id = std::to_string(daemon);
  return pg.query("SELECT count(*) FROM hystlab." + table + " WHERE daemon_id = $1", {id.c_str()}).integer(0, 0);
}

}  // namespace hystlab::lab_test
