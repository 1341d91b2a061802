#include "hystlab/daemon/shakedown.hpp"

#include <cmath>

namespace hystlab::daemon {
namespace {
double change_pct(double now, double before) {
  return std::fabs(before) > 0 ? 100.0 * std::fabs(now - before) / std::fabs(before) : (now == before ? 0.0 : 100.0);
}
}  // namespace

ShakedownStep ShakedownRule::add(double peak, double energy) noexcept {
  ShakedownStep s;
  s.cycle = ++cycles_;
  s.peak_force_N = peak;
  s.energy_Nmm = energy;
  if (cycles_ > 1) {
    s.peak_change_pct = change_pct(peak, last_peak_);
    s.energy_change_pct = change_pct(energy, last_energy_);
    const bool below = *s.peak_change_pct < t_.peak_force_change_pct && *s.energy_change_pct < t_.energy_change_pct;
    consecutive_ = below ? consecutive_ + 1 : 0;
  }
  last_peak_ = peak;
  last_energy_ = energy;
  s.consecutive = consecutive_;
  stable_ = t_.until && consecutive_ >= t_.consecutive;
  s.stable = stable_;
  s.last = stable_ || cycles_ >= t_.max_cycles;
  return s;
}

std::string ShakedownRule::summary() const {
  if (!t_.until) return "trained " + std::to_string(cycles_) + " cycle(s), as planned";
  if (stable_)
    return "the loop settled after " + std::to_string(cycles_) + " training cycle(s): peak force within " + domain::plan_number(t_.peak_force_change_pct) +
           " % and energy within " + domain::plan_number(t_.energy_change_pct) + " % for " + std::to_string(t_.consecutive) + " cycles in a row";
  return "the loop did not settle in " + std::to_string(cycles_) + " training cycle(s) (the maximum): peak force within " +
         domain::plan_number(t_.peak_force_change_pct) + " % and energy within " + domain::plan_number(t_.energy_change_pct) + " % for " +
         std::to_string(t_.consecutive) + " cycles in a row was not reached";
}

}  // namespace hystlab::daemon
