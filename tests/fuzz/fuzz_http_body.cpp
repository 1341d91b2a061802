// libFuzzer: every decoder of a request body, as the API runs them on what a client sends
// (web/src/request_body.hpp): the body parsed with its nesting limit, then the campaign/preview
// request and its plan, or the evaluation request with its displacements and its model
// (a table document or simplified-model parameters). Deep nesting, huge numbers, invalid UTF-8
// and truncated bodies are refused with the API's own errors; anything else thrown, or a crash,
// is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "../../web/src/request_body.hpp"
#include "hystlab/domain/plan.hpp"
#include "hystlab/models/formats.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/simplified_sma.hpp"

using namespace hystlab;

namespace {
void evaluate(const web::json& body) {
  const web::ModelSource source = web::decode_model_source(body);
  const std::vector<double> x = web::decode_displacements(body);
  if (source == web::ModelSource::table_document) {
    models::PreisachModel m(models::table_from_json(body["table"].dump()).table);
    for (const double v : x) (void)m.step(v);
  } else if (source == web::ModelSource::parameters) {
    models::SimplifiedSmaModel m(models::params_from_json(body["params"].dump()));
    for (const double v : x) (void)m.step(v);
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool evaluation = (data[0] & 1) != 0;  // which endpoint the rest of the input is posted to
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    const web::json body = web::parse_body(text, !evaluation);
    if (evaluation) {
      evaluate(body);
    } else {
      const web::PlanRequest r = web::decode_plan_request(body);
      (void)domain::parse_plan(r.plan);
    }
  } catch (const web::ApiError& e) {
    if (e.status != 400 && e.status != 413) std::abort();
  } catch (const domain::PlanError&) {
  } catch (const models::FormatError&) {
  } catch (const std::invalid_argument&) {  // a model's own validation (SmaParameters)
  }
  return 0;
}
