// A campaign's tables in a run's HDF5 file: the document exactly as stored (JSON text, what
// `hystlab eval --table` reads), and the same table as numbers for readers without a JSON parser:
// the grid's nodes, the Everett values as a square matrix (F(δ_i, δ_j) at [i][j], j <= i; NaN
// above the diagonal) and the force offset. The numbers come from the models' own reader, so they
// are the values the CLI evaluates (a diagonal rounded to 0 included).
#include <cmath>
#include <vector>

#include "h5_file.hpp"
#include "h5_layout.hpp"
#include "hystlab/db/run_h5.hpp"
#include "hystlab/db/store.hpp"
#include "hystlab/models/formats.hpp"

namespace hystlab::db::h5_layout {
namespace {
void write_table_numbers(hid_t g, const models::EverettTable& t) {
  const std::vector<double> nodes = t.grid().nodes();
  const std::size_t m = nodes.size();
  h5::attr_text(h5::write_column(g, "nodes_mm", std::span<const double>(nodes), 0).get(), "units", "mm");
  std::vector<double> square(m * m, std::nan(""));
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t j = 0; j <= i; ++j) square[i * m + j] = t.node_value(static_cast<int>(i), static_cast<int>(j));
  const h5::Handle e = h5::dataset_matrix(g, "everett_N", m, m, square.data());
  h5::attr_text(e.get(), "units", "N");
  h5::attr_text(e.get(), "label", "F(alpha_i, beta_j) = f_alpha - f_alpha_beta at [i][j], j <= i; NaN above the diagonal");
  h5::attr_text(h5::dataset_scalar(g, "force_offset_N", t.force_offset()).get(), "units", "N");
}

void write_table(ReadSource& store, hid_t tables, const TableInfo& info) {
  const h5::Handle g = h5::create_group(tables, "table_" + std::to_string(info.id));
  h5::attr_int(g.get(), "id", info.id);
  h5::attr_int(g.get(), "campaign", info.campaign.value_or(0));
  h5::attr_int(g.get(), "run", info.run.value_or(0));  // 0: none
  h5::attr_text(g.get(), "method", info.method);
  h5::attr_int(g.get(), "n", info.n);
  const double range[2] = {info.range_lo, info.range_hi};
  h5::attr_doubles(g.get(), "range_mm", range);
  h5::attr_text(g.get(), "created_at", info.created_at);
  const std::string doc = store.table_document(info.id).value_or("");
  h5::dataset_text(g.get(), "document", doc);
  h5::dataset_text(g.get(), "accuracy", info.accuracy_json.empty() ? "null" : info.accuracy_json);
  models::TableDocument t;
  try {
    t = models::table_from_json(doc);
  } catch (const std::exception& e) {
    throw H5ExportError(H5ExportError::Kind::write, "table " + std::to_string(info.id) + "'s stored document cannot be read: " + e.what());
  }
  const auto j = nlohmann::json::parse(doc, nullptr, false);  // the provenance as stored, not as re-read
  h5::dataset_text(g.get(), "provenance", j.is_object() && j.contains("provenance") ? j["provenance"].dump() : "null");
  write_table_numbers(g.get(), t.table);
}
}  // namespace

std::int64_t write_tables(ReadSource& store, hid_t file, std::int64_t campaign, int deflate_level) {
  (void)deflate_level;  // tables are small: stored whole, uncompressed
  const h5::Handle g = h5::create_group(file, "tables");
  std::int64_t n = 0;
  for (const TableInfo& t : store.tables(campaign)) {
    write_table(store, g.get(), t);
    ++n;
  }
  return n;
}

}  // namespace hystlab::db::h5_layout
