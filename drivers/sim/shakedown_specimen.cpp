#include "shakedown_specimen.hpp"

#include <cmath>

namespace hystlab::sim {

ShakedownSpecimen::ShakedownSpecimen(const models::SmaParameters& settled, double extra_N, double tau_cycles)
    : settled_(settled), extra_(extra_N), tau_(tau_cycles), model_(parameters_of(0)) {}

models::SmaParameters ShakedownSpecimen::parameters_of(int n) const noexcept {
  models::SmaParameters p = settled_;
  // f = C (T - M0): a forward force higher by e means M0 lower by e / C.
  const double e = extra_ * std::exp(-static_cast<double>(n) / tau_);
  p.Ms0 -= e / p.C;
  p.Mf0 -= e / p.C;
  return p;
}

void ShakedownSpecimen::reset() noexcept {
  cycles_ = 0;
  transformed_ = false;
  model_ = models::SimplifiedSmaModel(parameters_of(0));
}

double ShakedownSpecimen::step(double x) noexcept {
  const double f = model_.step(x);
  if (model_.martensite_fraction() > 0.5) transformed_ = true;
  if (transformed_ && model_.martensite_fraction() == 0.0 && model_.phase() == models::SimplifiedSmaModel::Phase::Elastic) {
    transformed_ = false;
    ++cycles_;
    models::SimplifiedSmaModel next(parameters_of(cycles_));  // from the virgin state, up the same austenite line
    (void)next.step(x);
    model_ = next;
    return model_.output();
  }
  return f;
}

}  // namespace hystlab::sim
