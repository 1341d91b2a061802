#pragma once
// Request bodies as the API takes them, apart from HTTP (so that a fuzzer drives exactly what a
// request reaches): JSON parsed with a nesting limit, and the documents of each POST checked
// field by field. Every refusal is an ApiError naming the field or the limit.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace hystlab::web {

using nlohmann::json;

// Thrown by handlers; turned into {"error": error, "detail": detail[, "field": field]} with this
// status.
struct ApiError : std::runtime_error {
  ApiError(int status_code, std::string error_text, const std::string& detail_text, std::string field_name = {})
      : std::runtime_error(detail_text), status(status_code), error(std::move(error_text)), field(std::move(field_name)) {}
  int status;
  std::string error, field;
};

// No document the API takes nests deeper than a few levels; 64 leaves room and keeps the parser,
// the destructor and dump() (each recursive) far from the stack's end. Measured before the
// limit: a body nesting arrays 100,000 deep killed hystlabd (10,000 under ASan).
inline constexpr std::size_t kMaxJsonDepth = 64;

// Throws ApiError(400) when the text opens more than max_depth arrays or objects at once
// (brackets inside strings do not count). Linear, no allocation.
void check_nesting(std::string_view text, std::size_t max_depth = kMaxJsonDepth);

// The body as a JSON object; an empty body as {} when allow_empty. Refuses (400) deep nesting,
// malformed JSON (invalid UTF-8 included), numbers out of range, and anything but an object.
[[nodiscard]] json parse_body(std::string_view body, bool allow_empty = false);

// POST /api/campaigns and /api/plans/preview: {"plan": {...}, "rig": "name"}.
struct PlanRequest {
  std::string rig;  // empty: the only rig
  json plan;
};
[[nodiscard]] PlanRequest decode_plan_request(const json& body);

// POST /api/evaluate: the displacements (finite numbers, at most kMaxEvaluate).
inline constexpr std::size_t kMaxEvaluate = 1'000'000;
[[nodiscard]] std::vector<double> decode_displacements(const json& body);
// Which model the evaluation names: exactly one of table_id, table, params.
enum class ModelSource { stored_table, table_document, parameters };
[[nodiscard]] ModelSource decode_model_source(const json& body);

}  // namespace hystlab::web
