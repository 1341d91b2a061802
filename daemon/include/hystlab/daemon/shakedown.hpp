#pragma once
// Training until the loop is stable: a superelastic specimen's plateau drifts for tens of cycles
// before it settles. Each training cycle's peak force and dissipated energy are compared with the
// previous cycle's; training ends once both changes stay below their thresholds for `consecutive`
// cycles in a row, or at max_cycles (then it says the loop did not settle). Pure: no I/O.
#include <optional>
#include <string>

#include "hystlab/domain/plan.hpp"

namespace hystlab::daemon {

struct ShakedownStep {
  int cycle = 0;  // 1-based
  double peak_force_N = 0, energy_Nmm = 0;
  std::optional<double> peak_change_pct, energy_change_pct;  // none for the first cycle
  int consecutive = 0;                                       // cycles in a row below both thresholds, this one included
  bool stable = false;                                       // the rule is met: training may end
  bool last = false;                                         // training ends after this cycle (stable, or the maximum reached)
};

class ShakedownRule {
 public:
  explicit ShakedownRule(const domain::Training& t) : t_(t) {}
  ShakedownStep add(double peak_force_N, double energy_Nmm) noexcept;
  [[nodiscard]] int cycles() const noexcept { return cycles_; }
  [[nodiscard]] bool stable() const noexcept { return stable_; }
  // What training came to, for the campaign's record.
  [[nodiscard]] std::string summary() const;

 private:
  domain::Training t_;
  int cycles_ = 0, consecutive_ = 0;
  bool stable_ = false;
  double last_peak_ = 0, last_energy_ = 0;
};

}  // namespace hystlab::daemon
