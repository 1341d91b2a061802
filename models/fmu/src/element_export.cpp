#include "hystlab/fmu/element_export.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "hystlab/fmu/fmu_archive.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/table_export.hpp"

namespace hystlab::fmu {

bool is_export_format(std::string_view f) { return std::find(kExportFormatList.begin(), kExportFormatList.end(), f) != kExportFormatList.end(); }

ExportedFile export_element(std::string_view document, std::string_view format, const std::string& name, const std::string& created,
                            std::optional<models::ElementKind> kind) {
  if (!is_export_format(format)) throw std::invalid_argument("'" + std::string(format) + "' is not " + std::string(kExportFormats));
  const auto j = nlohmann::json::parse(document.begin(), document.end(), nullptr, false);
  const bool looks_table = j.is_object() && j.contains("format");
  const bool table = kind ? *kind == models::ElementKind::Table : looks_table;
  if (table != looks_table) {  // not the kind named: its parser says what is missing
    if (table)
      (void)models::table_from_json(document);
    else
      (void)models::params_from_json(document);
  }
  if (format == "fmu") return {fmu_archive(document, FmuOptions{name, created}), "application/zip", true};
  if (table) {
    const models::TableDocument doc = models::table_from_json(document);
    if (format == "json") return {models::table_to_json(doc.table, doc.provenance).dump(2) + "\n", "application/json"};
    if (format == "csv") return {models::table_to_csv(doc.table, doc.provenance), "text/csv"};
    if (format == "m") return {models::table_to_matlab(doc.table, doc.provenance), "text/x-matlab"};
    return {models::table_to_c_header(doc.table, doc.provenance, name), "text/x-c"};
  }
  const models::SmaParameters p = models::params_from_json(document);
  const std::string source = j.is_object() && j.contains("source") && j["source"].is_string() ? j["source"].get<std::string>() : std::string();
  if (format == "json") return {models::params_to_json(p, source).dump(2) + "\n", "application/json"};
  if (format == "csv") return {models::params_to_csv(p), "text/csv"};
  if (format == "m") return {models::params_to_matlab(p), "text/x-matlab"};
  return {models::params_to_c_header(p, name), "text/x-c"};
}

}  // namespace hystlab::fmu
