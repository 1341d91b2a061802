#pragma once
// File formats of tables and model parameters, as pure text <-> object conversions (no I/O).
// Documented in docs/FORMATS.md. Errors throw FormatError naming the field and the reason.
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "hystlab/models/everett_table.hpp"
#include "hystlab/models/simplified_sma.hpp"

namespace hystlab::models {

struct FormatError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

inline constexpr std::string_view kTableFormat = "hystlab-everett-table";
// Version 1: a uniform grid (nodes_mm, when present, must be that grid). Version 2: the grid's own
// nodes in nodes_mm (any strictly increasing list). A uniform table is written as version 1, so
// that readers of version 1 still read it; this hystlab reads both.
inline constexpr int kTableVersion = 1;
inline constexpr int kTableVersionNodes = 2;
inline constexpr std::string_view kParamsModel = "simplified-sma";

struct TableProvenance {
  std::string source;                               // what was measured or simulated
  std::string method;                               // "fot", "virtual-fot", "lsq", ...
  std::string created;                              // ISO 8601 time, supplied by the caller
  std::string from;                                 // input file, run id, ...
  nlohmann::json extra = nlohmann::json::object();  // accuracy, drift, fit figures
  std::optional<double> temperature_C =
      std::nullopt;  // the specimen's temperature when identified, when known (an initializer: brace-initialized provenances need not name it)
};

struct TableDocument {
  EverettTable table;
  TableProvenance provenance;
};

[[nodiscard]] nlohmann::json table_to_json(const EverettTable& table, const TableProvenance& provenance);
[[nodiscard]] TableDocument table_from_json(std::string_view text);

[[nodiscard]] nlohmann::json params_to_json(const SmaParameters& p, const std::string& source);
// Reads the format of docs/examples/table1-params.json (docs/FORMATS.md) and validates the model.
[[nodiscard]] SmaParameters params_from_json(std::string_view text);

}  // namespace hystlab::models
