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

double BaseControl::start(double demand) const noexcept {
  if (!c_.closed) return demand;
  return std::min(c_.start_level * demand / response_, c_.max_drive_ratio * demand);
}

ControlBand BaseControl::band_of(double e) const noexcept {
  const double a = std::fabs(e);
  if (!(a <= c_.abort_pct)) return ControlBand::abort;  // NaN included
  if (a > c_.warning_pct) return ControlBand::warning;
  if (a > c_.tolerance_pct) return ControlBand::outside;
  return ControlBand::within;
}

ControlVerdict BaseControl::update(double demand, double drive, double measured) noexcept {
  ControlVerdict v;
  v.error_pct = demand > 0 ? (measured - demand) / demand * 100.0 : NAN;
  v.band = band_of(v.error_pct);
  v.next_drive_mm = drive;
  if (drive > 0 && measured > 0 && std::isfinite(measured)) response_ = measured / drive;
  if (!c_.closed || v.band == ControlBand::within || !(measured > 0)) return v;
  const double wanted = drive + c_.gain * (demand / response_ - drive);
  const double cap = c_.max_drive_ratio * demand;
  v.limited = wanted > cap;
  v.next_drive_mm = std::clamp(wanted, 1e-6, cap);
  return v;
}

}  // namespace hystlab::daemon
