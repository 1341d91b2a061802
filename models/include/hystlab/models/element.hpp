#pragma once
// A calibrated element: the model one document describes, an Everett table
// ("format": "hystlab-everett-table") or simplified-model parameters ("model": "simplified-sma"),
// as the C API, the FMU and the Python module load it. Pure: the text comes from the caller.
#include <memory>
#include <string>
#include <string_view>

#include "hystlab/models/hysteresis_model.hpp"

namespace hystlab::models {

enum class ElementKind { Table = 1, Params = 2 };

struct Element {
  ElementKind kind = ElementKind::Table;
  std::unique_ptr<HysteresisModel> model;  // at rest
  std::string canonical_json;              // the document re-written by this hystlab (validated)
  double rest_input_mm = 0.0;              // the input at rest: the table's lower end, or 0
  double lo_mm = 0.0, hi_mm = 0.0;         // a table's range (both 0 for parameters)
};

// Throws FormatError naming the field (or "not a JSON object") for a document of neither kind.
[[nodiscard]] Element element_from_json(std::string_view text);

}  // namespace hystlab::models
