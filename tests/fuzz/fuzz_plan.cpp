// libFuzzer: the campaign plan decoder (what POST /api/campaigns and `campaign submit` take)
// refuses any document with PlanError naming a field, never crashes; a plan it accepts is
// within its documented bounds.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "hystlab/domain/plan.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto j = nlohmann::json::parse(data, data + size, nullptr, false);
  if (j.is_discarded()) return 0;
  try {
    const hystlab::domain::Plan p = hystlab::domain::parse_plan(j);
    const bool sane = p.sample_rate_hz >= 1 && p.sample_rate_hz <= 10000 && std::isfinite(p.lo_mm) && std::isfinite(p.hi_mm) &&
                      p.limits.displacement_min_mm <= p.limits.displacement_max_mm;
    if (!sane) std::abort();  // accepted, but outside what the runner can trust
  } catch (const hystlab::domain::PlanError& e) {
    if (std::string(e.what()).rfind("plan: ", 0) != 0) std::abort();  // every refusal names the plan's field
  }
  return 0;
}
