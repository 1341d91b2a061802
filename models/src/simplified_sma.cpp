#include "hystlab/models/simplified_sma.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace hystlab::models {
namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

void require(bool ok, const std::string& field, const std::string& why) {
  if (!ok) throw std::invalid_argument("parameters: " + field + " " + why);
}
}  // namespace

SmaTransitions transitions(const SmaParameters& p) noexcept {
  SmaTransitions t;
  t.Ms.force = p.C * (p.T - p.Ms0);
  t.Mf.force = p.C * (p.T - p.Mf0);
  t.As.force = p.C * (p.T - p.As0);
  t.Af.force = p.C * (p.T - p.Af0);
  t.Ms.displacement = t.Ms.force / p.KA;
  t.Af.displacement = t.Af.force / p.KA;
  t.Mf.displacement = t.Mf.force / p.KM + p.dtr_max;  // erratum: the extracted Eq. 15 lost + δtr_max
  t.As.displacement = t.As.force / p.KM + p.dtr_max;  // erratum: the extracted Eq. 17 lost + δtr_max
  return t;
}

void validate(const SmaParameters& p) {
  const std::pair<const char*, double> fields[] = {{"KA_N_per_mm", p.KA}, {"KM_N_per_mm", p.KM}, {"dtr_max_mm", p.dtr_max},
                                                   {"C_N_per_degC", p.C}, {"Mf0_degC", p.Mf0},   {"Ms0_degC", p.Ms0},
                                                   {"As0_degC", p.As0},   {"Af0_degC", p.Af0},   {"T_degC", p.T}};
  for (const auto& [name, v] : fields) require(std::isfinite(v), name, "is not a finite number");
  require(p.KA > 0, "KA_N_per_mm", "must be > 0");
  require(p.KM > 0, "KM_N_per_mm", "must be > 0");
  require(p.dtr_max > 0, "dtr_max_mm", "must be > 0");
  require(p.C > 0, "C_N_per_degC", "must be > 0");
  require(p.Mf0 < p.Ms0, "Mf0_degC", "must be below Ms0_degC");
  require(p.As0 < p.Af0, "Af0_degC", "must be above As0_degC");
  require(p.T > p.Af0, "T_degC", "must be above Af0_degC (the model is superelastic: austenite at rest)");
  const SmaTransitions t = transitions(p);
  require(t.Mf.displacement > t.Ms.displacement, "dtr_max_mm", "is too small: the forward transformation would end (δMf) before it starts (δMs)");
  require(t.As.displacement > t.Af.displacement, "dtr_max_mm", "is too small: the reverse transformation would end (δAf) after it starts (δAs)");
  const double kmin = std::min(p.KA, p.KM);
  require(t.forward_slope() < kmin, "Mf0_degC", "gives a forward transformation line steeper than the elastic lines");
  require(t.reverse_slope() < kmin, "As0_degC", "gives a reverse transformation line steeper than the elastic lines");
  require(t.As.force <= t.Mf.force && t.Af.force < t.Ms.force, "As0_degC", "puts the reverse transformation above the forward one");
}

SimplifiedSmaModel::SimplifiedSmaModel(const SmaParameters& p) : p_(p), tr_(transitions(p)) {
  validate(p);
  reset();
}

void SimplifiedSmaModel::reset() noexcept {
  d_ = f_ = 0.0;
  enter_elastic(0.0, 0.0, 0.0);
}

void SimplifiedSmaModel::enter_elastic(double anchor_d, double anchor_f, double xi) noexcept {
  phase_ = Phase::Elastic;
  xi_ = xi;
  anchor_d_ = anchor_d;
  anchor_f_ = anchor_f;
  k_ = elastic_stiffness(xi);
}

void SimplifiedSmaModel::enter_transformation(Phase phase, double d) noexcept {
  phase_ = phase;
  entry_d_ = d;
  entry_xi_ = xi_;
}

double SimplifiedSmaModel::forward_meet() const noexcept {
  if (xi_ >= 1.0) return kInf;
  const double s = tr_.forward_slope();
  const double d = (tr_.Ms.force - s * tr_.Ms.displacement - anchor_f_ + k_ * anchor_d_) / (k_ - s);
  // Past δMf the forward line does not exist: such a line stays elastic (documented).
  return d < tr_.Mf.displacement ? d : kInf;
}

double SimplifiedSmaModel::reverse_meet() const noexcept {
  if (xi_ <= 0.0) return -kInf;
  const double s = tr_.reverse_slope();
  const double d = (tr_.Af.force - s * tr_.Af.displacement - anchor_f_ + k_ * anchor_d_) / (k_ - s);
  return d > tr_.Af.displacement ? d : -kInf;
}

bool SimplifiedSmaModel::advance_elastic(double x) noexcept {
  const bool up = x > d_;
  const double meet = up ? forward_meet() : reverse_meet();
  if (up ? meet <= x : meet >= x) {  // the transformation line is reached on the way
    if (up ? meet > d_ : meet < d_) {
      d_ = meet;
      f_ = anchor_f_ + k_ * (d_ - anchor_d_);
    }
    enter_transformation(up ? Phase::Forward : Phase::Reverse, d_);
    return false;
  }
  d_ = x;
  f_ = anchor_f_ + k_ * (d_ - anchor_d_);
  return true;
}

bool SimplifiedSmaModel::advance_forward(double x) noexcept {
  if (x < d_) {  // reversal inside the transformation: leave on the elastic line at this ξ
    enter_elastic(d_, f_, xi_);
    return false;
  }
  const double end = tr_.Mf.displacement;
  if (x >= end) {
    d_ = end;
    f_ = tr_.Mf.force;
    enter_elastic(end, tr_.Mf.force, 1.0);  // the martensite line
    return x == end;
  }
  d_ = x;
  f_ = forward_force(x);
  xi_ = entry_xi_ + (1.0 - entry_xi_) * (x - entry_d_) / (end - entry_d_);
  return true;
}

bool SimplifiedSmaModel::advance_reverse(double x) noexcept {
  if (x > d_) {
    enter_elastic(d_, f_, xi_);
    return false;
  }
  const double end = tr_.Af.displacement;
  if (x <= end) {
    d_ = end;
    f_ = tr_.Af.force;
    enter_elastic(end, tr_.Af.force, 0.0);  // the austenite line
    return x == end;
  }
  d_ = x;
  f_ = reverse_force(x);
  xi_ = entry_d_ > end ? entry_xi_ * (x - end) / (entry_d_ - end) : 0.0;
  return true;
}

double SimplifiedSmaModel::step(double x) noexcept {
  if (std::isnan(x)) return std::numeric_limits<double>::quiet_NaN();
  // Each pass crosses at most one phase boundary; a step can cross only a few.
  for (int pass = 0; pass < 16 && x != d_; ++pass) {
    bool reached = false;
    switch (phase_) {
      case Phase::Elastic:
        reached = advance_elastic(x);
        break;
      case Phase::Forward:
        reached = advance_forward(x);
        break;
      case Phase::Reverse:
        reached = advance_reverse(x);
        break;
    }
    if (reached) break;
  }
  return f_;
}

}  // namespace hystlab::models

namespace hystlab::models {
namespace {
constexpr double kSmaStateKind = 2.0;
constexpr std::size_t kSmaStateSize = 10;
}  // namespace

std::vector<double> SimplifiedSmaModel::save_state() const {
  return {kSmaStateKind, static_cast<double>(static_cast<int>(phase_)), d_, f_, xi_, anchor_d_, anchor_f_, k_, entry_d_, entry_xi_};
}

// Checked before anything is taken: a refused state leaves the model as it was.
void SimplifiedSmaModel::restore_state(std::span<const double> s) {
  if (s.size() != kSmaStateSize || s[0] != kSmaStateKind) throw std::invalid_argument("model state: not the state of a simplified SMA model");
  if (s[1] != 0.0 && s[1] != 1.0 && s[1] != 2.0) throw std::invalid_argument("model state: the phase is not 0, 1 or 2");
  for (std::size_t k = 2; k < s.size(); ++k)
    if (!std::isfinite(s[k])) throw std::invalid_argument("model state: value " + std::to_string(k) + " is not a finite number");
  if (s[4] < 0.0 || s[4] > 1.0 || s[9] < 0.0 || s[9] > 1.0) throw std::invalid_argument("model state: a martensite fraction is outside [0, 1]");
  phase_ = static_cast<Phase>(static_cast<int>(s[1]));
  d_ = s[2];
  f_ = s[3];
  xi_ = s[4];
  anchor_d_ = s[5];
  anchor_f_ = s[6];
  k_ = s[7];
  entry_d_ = s[8];
  entry_xi_ = s[9];
}

}  // namespace hystlab::models
