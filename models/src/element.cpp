#include "hystlab/models/element.hpp"

#include <nlohmann/json.hpp>

#include "hystlab/models/formats.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/simplified_sma.hpp"

namespace hystlab::models {

Element element_from_json(std::string_view text) {
  const auto j = nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) throw FormatError("element: not a JSON object (a table or a parameter set)");
  Element e;
  if (j.contains("format")) {
    TableDocument doc = table_from_json(text);
    e.kind = ElementKind::Table;
    e.canonical_json = table_to_json(doc.table, doc.provenance).dump();
    e.lo_mm = e.rest_input_mm = doc.table.grid().lo;
    e.hi_mm = doc.table.grid().hi;
    e.model = std::make_unique<PreisachModel>(std::make_shared<const EverettTable>(std::move(doc.table)));
    return e;
  }
  const SmaParameters p = params_from_json(text);
  e.kind = ElementKind::Params;
  const auto source = j.find("source");
  e.canonical_json = params_to_json(p, source != j.end() && source->is_string() ? source->get<std::string>() : std::string()).dump();
  e.model = std::make_unique<SimplifiedSmaModel>(p);
  return e;
}

}  // namespace hystlab::models
