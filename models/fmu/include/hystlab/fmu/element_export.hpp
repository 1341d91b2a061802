#pragma once
// Every export format of a calibrated element (a table or simplified-model parameters), named
// once for the CLI (`hystlab export`, `hystlab tables export`) and the HTTP API
// (GET /api/tables/ID/export): json, csv, m, h and fmu. Pure: returns the bytes.
#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "hystlab/models/element.hpp"

namespace hystlab::fmu {

struct ExportedFile {
  std::string bytes;
  std::string media_type;  // for HTTP
  bool binary = false;     // not for a terminal
};

// Every format, once: is_export_format accepts these and no other; the CLI's help lists them.
inline constexpr std::array<std::string_view, 5> kExportFormatList{"json", "csv", "m", "h", "fmu"};
inline constexpr std::string_view kExportFormats = "json, csv, m, h or fmu";
[[nodiscard]] bool is_export_format(std::string_view format);

// document: a table or parameter set (validated; FormatError names the field); kind: the one the
// user named, when they named one (a document of the other kind is then refused by its parser,
// naming the missing field). name: the C header's prefix and the FMU's model name.
// Throws std::invalid_argument for an unknown format ("'x' is not json, csv, m, h or fmu").
[[nodiscard]] ExportedFile export_element(std::string_view document, std::string_view format, const std::string& name, const std::string& created = {},
                                          std::optional<models::ElementKind> kind = {});

}  // namespace hystlab::fmu
