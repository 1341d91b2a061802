#include "hystlab/models/inverse.hpp"

#include <cmath>

namespace hystlab::models {

InverseResult invert(const HysteresisModel& model, double target, double lo, double hi, double tol) noexcept {
  InverseResult r;
  if (!std::isfinite(target) || !(hi > lo)) {
    r.error = std::make_error_code(std::errc::invalid_argument);
    return r;
  }
  double f_lo = model.peek(lo), f_hi = model.peek(hi);
  if (target < f_lo || target > f_hi) {
    r.error = std::make_error_code(std::errc::result_out_of_range);
    r.displacement = target < f_lo ? lo : hi;
    r.force = target < f_lo ? f_lo : f_hi;
    return r;
  }
  // Invariant: peek(lo) <= target <= peek(hi).
  while (hi - lo > tol && r.iterations < 200) {
    const double mid = 0.5 * (lo + hi);
    const double f = model.peek(mid);
    if (f < target) {
      lo = mid;
      f_lo = f;
    } else {
      hi = mid;
      f_hi = f;
    }
    ++r.iterations;
  }
  // The closer end in force (a flat stretch can make both ends valid).
  const bool take_lo = std::fabs(f_lo - target) <= std::fabs(f_hi - target);
  r.displacement = take_lo ? lo : hi;
  r.force = take_lo ? f_lo : f_hi;
  return r;
}

}  // namespace hystlab::models
