#include "request_body.hpp"

#include <cmath>

namespace hystlab::web {

void check_nesting(std::string_view text, std::size_t max_depth) {
  std::size_t depth = 0;
  bool in_string = false, escaped = false;
  for (const char ch : text) {
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (ch == '\\')
        escaped = true;
      else if (ch == '"')
        in_string = false;
      continue;
    }
    if (ch == '"')
      in_string = true;
    else if (ch == '[' || ch == '{') {
      if (++depth > max_depth)
        throw ApiError(400, "malformed JSON", "the request body nests arrays or objects deeper than " + std::to_string(max_depth) + " levels");
    } else if ((ch == ']' || ch == '}') && depth > 0) {
      --depth;
    }
  }
}

json parse_body(std::string_view body, bool allow_empty) {
  if (allow_empty && body.find_first_not_of(" \t\r\n") == std::string_view::npos) return json::object();
  check_nesting(body);
  json j;
  try {
    j = json::parse(body);
  } catch (const json::out_of_range& e) {  // 1e400: "number overflow"
    throw ApiError(400, "malformed JSON", std::string("a number in the request body is out of range: ") + e.what());
  } catch (const json::exception& e) {
    throw ApiError(400, "malformed JSON", std::string("the request body is not valid JSON: ") + e.what());
  }
  if (!j.is_object()) throw ApiError(400, "malformed JSON", "the request body must be a JSON object");
  return j;
}

PlanRequest decode_plan_request(const json& body) {
  for (const auto& [k, _] : body.items())
    if (k != "plan" && k != "rig") throw ApiError(400, "invalid request", k + ": not a known field (plan, rig)", k);
  if (!body.contains("plan") || !body["plan"].is_object()) throw ApiError(400, "invalid request", "plan: must be a JSON object (a campaign plan)", "plan");
  if (body.contains("rig") && !body["rig"].is_string()) throw ApiError(400, "invalid request", "rig: must be a rig's name", "rig");
  return {body.value("rig", std::string()), body["plan"]};
}

std::vector<double> decode_displacements(const json& body) {
  const auto it = body.find("displacement_mm");
  if (it == body.end() || !it->is_array() || it->empty())
    throw ApiError(400, "invalid request", "displacement_mm: must be a non-empty array of displacements in mm", "displacement_mm");
  if (it->size() > kMaxEvaluate)
    throw ApiError(400, "invalid request", "displacement_mm: at most " + std::to_string(kMaxEvaluate) + " values per request", "displacement_mm");
  std::vector<double> x;
  x.reserve(it->size());
  for (std::size_t k = 0; k < it->size(); ++k) {
    const json& v = (*it)[k];
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      throw ApiError(400, "invalid request", "displacement_mm[" + std::to_string(k) + "]: must be a finite number", "displacement_mm");
    x.push_back(v.get<double>());
  }
  return x;
}

ModelSource decode_model_source(const json& body) {
  for (const auto& [k, _] : body.items())
    if (k != "table_id" && k != "table" && k != "params" && k != "displacement_mm")
      throw ApiError(400, "invalid request", k + ": not a known field (table_id, table, params, displacement_mm)", k);
  const int given = static_cast<int>(body.contains("table_id")) + static_cast<int>(body.contains("table")) + static_cast<int>(body.contains("params"));
  if (given != 1) throw ApiError(400, "invalid request", "give exactly one of table_id, table (a table document) or params (simplified-model parameters)");
  if (body.contains("table_id")) {
    if (!body["table_id"].is_number_integer()) throw ApiError(400, "invalid request", "table_id: must be a table's id", "table_id");
    return ModelSource::stored_table;
  }
  if (body.contains("table")) {
    if (!body["table"].is_object()) throw ApiError(400, "invalid request", "table: must be a table document (JSON object)", "table");
    return ModelSource::table_document;
  }
  if (!body["params"].is_object()) throw ApiError(400, "invalid request", "params: must be a parameters document (JSON object)", "params");
  return ModelSource::parameters;
}

}  // namespace hystlab::web
