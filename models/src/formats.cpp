#include "hystlab/models/formats.hpp"

#include <cmath>
#include <sstream>

namespace hystlab::models {
namespace {
using nlohmann::json;

[[noreturn]] void fail(const std::string& what, const std::string& msg) { throw FormatError(what + ": " + msg); }

json parse(std::string_view text, const std::string& what) {
  try {
    json j = json::parse(text.begin(), text.end());
    if (!j.is_object()) fail(what, "the document is not a JSON object");
    return j;
  } catch (const json::parse_error& e) {
    fail(what, std::string("not valid JSON (") + e.what() + ")");
  }
}

const json& field(const json& j, const char* name, const std::string& what) {
  const auto it = j.find(name);
  if (it == j.end()) fail(what, std::string("missing field '") + name + "'");
  return *it;
}

double number(const json& v, const std::string& name, const std::string& what) {
  if (!v.is_number()) fail(what, "'" + name + "' must be a number");
  const double d = v.get<double>();
  if (!std::isfinite(d)) fail(what, "'" + name + "' is not a finite number");
  return d;
}

std::string text_or_empty(const json& j, const char* name) {
  const auto it = j.find(name);
  return it != j.end() && it->is_string() ? it->get<std::string>() : std::string();
}
}  // namespace

TableDocument parse_table(std::string_view text);
SmaParameters parse_params(std::string_view text);

json table_to_json(const EverettTable& t, const TableProvenance& p) {
  const Grid& g = t.grid();
  json nodes = json::array(), rows = json::array();
  for (int i = 0; i <= g.n; ++i) {
    nodes.push_back(g.node(i));
    json row = json::array();
    for (int j = 0; j <= i; ++j) row.push_back(t.node_value(i, j));
    rows.push_back(std::move(row));
  }
  json prov{{"source", p.source}, {"method", p.method}, {"created", p.created}, {"from", p.from}, {"n", g.n}, {"details", p.extra}};
  if (p.temperature_C) prov["temperature_C"] = *p.temperature_C;
  return json{{"format", kTableFormat},
              {"version", g.uniform() ? kTableVersion : kTableVersionNodes},
              {"units", {{"displacement", "mm"}, {"force", "N"}}},
              {"range_mm", {g.lo, g.hi}},
              {"subdivisions", g.n},
              {"nodes_mm", std::move(nodes)},
              {"force_offset_N", t.force_offset()},
              {"rows", std::move(rows)},
              {"provenance", std::move(prov)}};
}

TableDocument table_from_json(std::string_view text) {
  try {
    return parse_table(text);
  } catch (const nlohmann::json::exception& e) {  // a number too large, a field of the wrong type, ...
    throw FormatError(std::string("table: malformed (") + e.what() + ")");
  }
}

TableDocument parse_table(std::string_view text) {
  const std::string what = "table";
  const json j = parse(text, what);
  const json& fmt = field(j, "format", what);
  if (!fmt.is_string() || fmt.get<std::string>() != kTableFormat) fail(what, "'format' is " + fmt.dump() + ", expected \"" + std::string(kTableFormat) + "\"");
  const json& ver = field(j, "version", what);
  if (!ver.is_number_integer() || (ver.get<int>() != kTableVersion && ver.get<int>() != kTableVersionNodes))
    fail(what, "unknown format version " + ver.dump() + " (this hystlab reads versions " + std::to_string(kTableVersion) + " and " +
                   std::to_string(kTableVersionNodes) + ")");
  const bool own_nodes = ver.get<int>() == kTableVersionNodes;
  if (const auto u = j.find("units"); u != j.end()) {
    if (!u->is_object() || u->value("displacement", "mm") != "mm" || u->value("force", "N") != "N")
      fail(what, "'units' must be {\"displacement\": \"mm\", \"force\": \"N\"}");
  }
  const json& range = field(j, "range_mm", what);
  if (!range.is_array() || range.size() != 2) fail(what, "'range_mm' must be [start, end]");
  const double lo = number(range[0], "range_mm[0]", what), hi = number(range[1], "range_mm[1]", what);
  const json& sub = field(j, "subdivisions", what);
  if (!sub.is_number_integer() || sub.get<long long>() < 1 || sub.get<long long>() > 2000) fail(what, "'subdivisions' must be an integer from 1 to 2000");
  Grid g;
  try {
    g = Grid::make(lo, hi, sub.get<int>());
  } catch (const std::invalid_argument& e) {
    fail(what, e.what());
  }
  const auto nodes = j.find("nodes_mm");
  if (own_nodes && nodes == j.end()) fail(what, "version 2 needs 'nodes_mm' (the grid's nodes)");
  if (nodes != j.end()) {
    if (!nodes->is_array() || nodes->size() != static_cast<std::size_t>(g.n) + 1) fail(what, "'nodes_mm' must hold subdivisions + 1 values");
    std::vector<double> x;
    for (std::size_t i = 0; i < nodes->size(); ++i) {
      const double v = number((*nodes)[i], "nodes_mm[" + std::to_string(i) + "]", what);
      if (i > 0 && !(v > x.back())) fail(what, "non-monotone grid: nodes_mm[" + std::to_string(i) + "] is not above nodes_mm[" + std::to_string(i - 1) + "]");
      if (!own_nodes && std::fabs(v - g.node(static_cast<int>(i))) > 1e-9 * (hi - lo) + 1e-12)
        fail(what, "nodes_mm[" + std::to_string(i) + "] is off the uniform grid of range_mm and subdivisions (a grid of its own is version 2)");
      x.push_back(v);
    }
    if (own_nodes) {
      if (x.front() != lo || x.back() != hi) fail(what, "nodes_mm must run from range_mm[0] to range_mm[1]");
      g = Grid::from_nodes(x);
    }
  }
  const json& rows = field(j, "rows", what);
  if (!rows.is_array() || rows.size() != static_cast<std::size_t>(g.n) + 1) fail(what, "'rows' must hold subdivisions + 1 rows");
  std::vector<double> values;
  values.reserve(g.node_count());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (!rows[i].is_array() || rows[i].size() != i + 1) fail(what, "rows[" + std::to_string(i) + "] must hold " + std::to_string(i + 1) + " values");
    for (std::size_t k = 0; k <= i; ++k) values.push_back(number(rows[i][k], "rows[" + std::to_string(i) + "][" + std::to_string(k) + "]", what));
  }
  double offset = 0.0;
  if (const auto o = j.find("force_offset_N"); o != j.end()) offset = number(*o, "force_offset_N", what);
  TableDocument doc;
  try {
    doc.table = EverettTable(g, std::move(values), offset);
  } catch (const std::invalid_argument& e) {
    throw FormatError(e.what());
  }
  if (const auto p = j.find("provenance"); p != j.end() && p->is_object()) {
    doc.provenance.source = text_or_empty(*p, "source");
    doc.provenance.method = text_or_empty(*p, "method");
    doc.provenance.created = text_or_empty(*p, "created");
    doc.provenance.from = text_or_empty(*p, "from");
    if (const auto d = p->find("details"); d != p->end()) doc.provenance.extra = *d;
    if (const auto t = p->find("temperature_C"); t != p->end()) doc.provenance.temperature_C = number(*t, "provenance.temperature_C", what);
  }
  return doc;
}

json params_to_json(const SmaParameters& p, const std::string& source) {
  return json{{"model", kParamsModel},   {"source", source},    {"KA_N_per_mm", p.KA}, {"KM_N_per_mm", p.KM},
              {"dtr_max_mm", p.dtr_max}, {"C_N_per_degC", p.C}, {"Mf0_degC", p.Mf0},   {"Ms0_degC", p.Ms0},
              {"As0_degC", p.As0},       {"Af0_degC", p.Af0},   {"T_degC", p.T}};
}

SmaParameters params_from_json(std::string_view text) {
  try {
    return parse_params(text);
  } catch (const nlohmann::json::exception& e) {
    throw FormatError(std::string("parameters: malformed (") + e.what() + ")");
  }
}

SmaParameters parse_params(std::string_view text) {
  const std::string what = "parameters";
  const json j = parse(text, what);
  if (const auto m = j.find("model"); m != j.end() && (!m->is_string() || m->get<std::string>() != kParamsModel))
    fail(what, "'model' is " + m->dump() + ", expected \"" + std::string(kParamsModel) + "\"");
  SmaParameters p;
  const std::pair<const char*, double*> fields[] = {{"KA_N_per_mm", &p.KA}, {"KM_N_per_mm", &p.KM}, {"dtr_max_mm", &p.dtr_max},
                                                    {"C_N_per_degC", &p.C}, {"Mf0_degC", &p.Mf0},   {"Ms0_degC", &p.Ms0},
                                                    {"As0_degC", &p.As0},   {"Af0_degC", &p.Af0},   {"T_degC", &p.T}};
  for (const auto& [name, dst] : fields) *dst = number(field(j, name, what), name, what);
  try {
    validate(p);
  } catch (const std::invalid_argument& e) {
    throw FormatError(e.what());
  }
  return p;
}

}  // namespace hystlab::models
