#include "hystlab/daemon/safety.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hystlab::daemon {
namespace {
std::string fmt(const char* f, double a, double b) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}
}  // namespace

std::optional<std::string> SafetyEnvelope::check(double x, double f, double t, double answered) {
  if (x < l_.displacement_min_mm || x > l_.displacement_max_mm)
    return fmt("displacement %.4g mm outside the limits (%.4g mm)", x, x < l_.displacement_min_mm ? l_.displacement_min_mm : l_.displacement_max_mm);
  if (std::fabs(f) > l_.force_max_N) return fmt("force %.4g N beyond the limit of %.4g N", f, l_.force_max_N);
  if (!have_ref_) {
    ref_x_ = x, ref_t_ = t, have_ref_ = true;
    return std::nullopt;
  }
  if (t - ref_t_ < window_) return std::nullopt;  // not enough time yet for a meaningful rate
  // Over the longest time the motion can have taken: from the earlier sample's request to this
  // one's answer. A slow answer (the controller's values of when it finally answered) then
  // cannot pass for a fast motion; a real runaway still trips, a transaction later at most.
  const double rate = std::fabs(x - ref_x_) / (std::max(t, answered) - ref_t_);
  ref_x_ = x, ref_t_ = t;
  if (rate > l_.rate_max_mm_s) return fmt("rate %.4g mm/s beyond the limit of %.4g mm/s", rate, l_.rate_max_mm_s);
  return std::nullopt;
}

}  // namespace hystlab::daemon
