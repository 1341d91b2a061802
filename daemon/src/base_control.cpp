#include "hystlab/daemon/base_control.hpp"

#include <algorithm>
#include <cmath>

namespace hystlab::daemon {

const char* to_string(ControlBand b) noexcept {
  switch (b) {
    case ControlBand::within:
      return "within tolerance";
    case ControlBand::outside:
      return "outside tolerance";
    case ControlBand::warning:
      return "warning";
    case ControlBand::abort:
      return "abort";
  }
  return "?";
}

double BaseControl::response_at(double f) const noexcept {
  if (n_ == 0) return 1.0;
  const auto* end = learnt_.begin() + n_;
  const auto* hi = std::lower_bound(learnt_.begin(), end, f, [](const auto& e, double x) { return e.first < x; });
  if (hi == learnt_.begin()) return hi->second;
  if (hi == end) return (end - 1)->second;
  const auto* lo = hi - 1;
  const double u = std::log(f / lo->first) / std::log(hi->first / lo->first);
  return lo->second + u * (hi->second - lo->second);
}

void BaseControl::learn(double f, double r) noexcept {
  auto* end = learnt_.begin() + n_;
  auto* at = std::lower_bound(learnt_.begin(), end, f, [](const auto& e, double x) { return e.first < x; });
  // A frequency within 1 % of one learnt is that one (a continuous sweep moves every window).
  for (auto* near : {at, at == learnt_.begin() ? at : at - 1})
    if (near != end && std::fabs(near->first - f) <= 0.01 * f) {
      *near = {f, r};
      return;
    }
  if (n_ == kLearnt) {  // full: the nearest entry gives way
    auto* near = at == end ? end - 1 : at;
    *near = {f, r};
    std::sort(learnt_.begin(), end, [](const auto& a, const auto& b) { return a.first < b.first; });
    return;
  }
  std::move_backward(at, end, end + 1);
  *at = {f, r};
  ++n_;
}

double BaseControl::start(double f, double demand) const noexcept {
  if (!c_.closed) return demand;
  const double drive = n_ == 0 ? c_.start_level * demand : demand / response_at(f);
  return std::min(drive, c_.max_drive_ratio * demand);
}

ControlBand BaseControl::band_of(double e) const noexcept {
  const double a = std::fabs(e);
  if (!(a <= c_.abort_pct)) return ControlBand::abort;  // NaN included
  if (a > c_.warning_pct) return ControlBand::warning;
  if (a > c_.tolerance_pct) return ControlBand::outside;
  return ControlBand::within;
}

ControlVerdict BaseControl::update(double f, double demand, double drive, double measured) noexcept {
  ControlVerdict v;
  v.error_pct = demand > 0 ? (measured - demand) / demand * 100.0 : NAN;
  v.band = band_of(v.error_pct);
  v.converged = std::fabs(v.error_pct) <= c_.converge_pct;
  v.next_drive_mm = drive;
  if (!(drive > 0 && measured > 0 && std::isfinite(measured))) return v;
  learn(f, measured / drive);
  if (!c_.closed) return v;
  const double wanted = drive + c_.gain * (demand / response_at(f) - drive);
  const double cap = c_.max_drive_ratio * demand;
  v.limited = wanted > cap;
  v.next_drive_mm = std::clamp(wanted, 1e-6, cap);
  return v;
}

}  // namespace hystlab::daemon
