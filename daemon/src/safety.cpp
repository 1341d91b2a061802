#include "hystlab/daemon/safety.hpp"

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

std::optional<std::string> SafetyEnvelope::check(double x, double f, double dt) {
  std::optional<std::string> trip;
  if (x < l_.displacement_min_mm || x > l_.displacement_max_mm)
    trip = fmt("displacement %.4g mm outside the limits (%.4g mm)", x, x < l_.displacement_min_mm ? l_.displacement_min_mm : l_.displacement_max_mm);
  else if (std::fabs(f) > l_.force_max_N)
    trip = fmt("force %.4g N beyond the limit of %.4g N", f, l_.force_max_N);
  else if (have_prev_ && dt > 0 && std::fabs(x - prev_x_) / dt > l_.rate_max_mm_s)
    trip = fmt("rate %.4g mm/s beyond the limit of %.4g mm/s", std::fabs(x - prev_x_) / dt, l_.rate_max_mm_s);
  prev_x_ = x;
  have_prev_ = true;
  return trip;
}

}  // namespace hystlab::daemon
