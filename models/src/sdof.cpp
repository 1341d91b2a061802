#include "hystlab/models/sdof.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

#include "hystlab/models/everett_table.hpp"
#include "hystlab/models/preisach_model.hpp"
#include "hystlab/models/sine_fit.hpp"

namespace hystlab::models {
namespace {
constexpr double kMmPerS2PerNPerKg = 1000.0;  // 1 N/kg = 1 m/s² = 1000 mm/s²

[[noreturn]] void fail(const std::string& field, const std::string& why) { throw std::invalid_argument(field + ": " + why); }

void check_finite(double v, const char* field, double lo, const char* why) {
  if (!std::isfinite(v) || v < lo) fail(field, why);
}

std::string short_num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}
}  // namespace

SdofSystem::SdofSystem(std::vector<SdofSpring> springs, const SdofOptions& o) : springs_(std::move(springs)), opt_(o) {
  if (springs_.empty()) fail("springs", "at least one spring is needed");
  if (!(o.mass_kg > 0) || !std::isfinite(o.mass_kg)) fail("mass_kg", "must be a positive number of kg");
  check_finite(o.damping_N_s_per_mm, "damping_N_s_per_mm", 0.0, "must be zero or a positive number of N·s/mm");
  check_finite(o.preload_mm, "preload_mm", 0.0, "must be zero or a positive compression in mm");
  if (!(o.dt_s > 0) || o.dt_s > 0.1) fail("dt_s", "must be a step above 0 and at most 0.1 s");
  double k_sum = 0;
  for (std::size_t i = 0; i < springs_.size(); ++i) {
    if (!springs_[i].model) fail("springs[" + std::to_string(i) + "]", "has no model");
    const double k = springs_[i].max_stiffness_N_per_mm;
    if (!(k > 0) || !std::isfinite(k)) fail("springs[" + std::to_string(i) + "]", "needs a positive stiffness bound");
    k_sum += k;
  }
  omega_max_ = std::sqrt(kMmPerS2PerNPerKg * k_sum / o.mass_kg);
  if (o.dt_s * omega_max_ >= 1.0)
    fail("dt_s", "a step of " + short_num(o.dt_s) + " s is unstable for this system: dt·ω_max = " + short_num(o.dt_s * omega_max_) +
                     " (ω_max = sqrt(1000·Σk_max/m) = " + short_num(omega_max_) + " rad/s) must stay below 1; use dt ≤ " + short_num(0.5 / omega_max_) + " s");
  // Load the springs monotonically from rest to the preload: the weight is what they then carry.
  for (auto& s : springs_) s.model->reset();
  group_tables();  // after the reset: every spring's memory is its table's start
  constexpr int kLoadSteps = 200;
  double f = 0;
  for (int k = 1; k <= kLoadSteps; ++k) f = spring_force(o.preload_mm * k / kLoadSteps);
  weight_ = f;
  lift_off_ = 0;
  s_.delta = o.preload_mm;
  s_.force = f;
}

void SdofSystem::group_tables() {
  std::vector<TableGroup> groups;
  for (const auto& s : springs_) {
    auto* p = dynamic_cast<PreisachModel*>(s.model.get());
    if (!p) return;  // a spring of another kind: every spring through the interface
    const auto same =
        std::find_if(groups.begin(), groups.end(), [p](const TableGroup& g) { return &g.model->table() == &p->table() && g.model->options() == p->options(); });
    if (same != groups.end())
      same->count += 1;
    else
      groups.push_back({p, 1.0});
  }
  tables_ = std::move(groups);
}

double SdofSystem::spring_force(double delta) noexcept {
  if (delta < 0) {
    ++lift_off_;  // the mass has left the springs: they only push
    delta = 0;
  }
  double f = 0;
  if (!tables_.empty()) {
    for (const TableGroup& g : tables_) f += g.count * g.model->step(delta);
    return f;
  }
  for (auto& s : springs_) f += s.model->step(delta);
  return f;
}

void SdofSystem::set_base(double amplitude_mm, double frequency_hz) noexcept {
  amplitude_ = amplitude_mm;
  omega_ = 2 * std::numbers::pi * frequency_hz;
  s_.y = amplitude_ * std::sin(phase_);  // continuous; the base's velocity takes the new value now
  s_.y_dot = amplitude_ * omega_ * std::cos(phase_);
}

void SdofSystem::step() noexcept {
  const double dt = opt_.dt_s, c = opt_.damping_N_s_per_mm, g = kMmPerS2PerNPerKg / opt_.mass_kg;
  const SdofState s0 = s_;
  SdofState& s1 = s_;
  s1.t = s0.t + dt;
  s1.x = s0.x + s0.v * dt + 0.5 * s0.a * dt * dt;
  phase_ += omega_ * dt;
  s1.y = amplitude_ * std::sin(phase_);
  s1.y_dot = amplitude_ * omega_ * std::cos(phase_);
  s1.delta = opt_.preload_mm + s1.y - s1.x;
  s1.force = spring_force(s1.delta);  // the springs' memory moves once, here
  s1.v = (s0.v + 0.5 * dt * s0.a + 0.5 * dt * g * (s1.force - weight_ + c * s1.y_dot)) / (1.0 + 0.5 * dt * g * c);
  s1.a = g * (s1.force - weight_ + c * (s1.y_dot - s1.v));
  const double r0 = s0.y_dot - s0.v, r1 = s1.y_dot - s1.v;
  e_.input += 0.5 * dt * ((s0.force + c * r0) * s0.y_dot + (s1.force + c * r1) * s1.y_dot);
  e_.spring += 0.5 * (s0.force + s1.force) * (s1.delta - s0.delta);
  e_.damper += 0.5 * dt * c * (r0 * r0 + r1 * r1);
  e_.kinetic = 0.5 * opt_.mass_kg * s1.v * s1.v * 1e-3;  // kg·(mm/s)² = 1e-3 N·mm
  e_.gravity = weight_ * s1.x;
}

void SdofSystem::run_for(double seconds) noexcept {
  const auto n = static_cast<long>(std::llround(seconds / opt_.dt_s));
  for (long k = 0; k < n; ++k) step();
}

SteadyResponse steady_response(SdofSystem& sys, double amplitude_mm, double frequency_hz, int settle_cycles, int measured_cycles) {
  if (!(frequency_hz > 0) || !std::isfinite(frequency_hz)) fail("frequency_hz", "must be a positive frequency");
  if (!(amplitude_mm > 0) || !std::isfinite(amplitude_mm)) fail("amplitude_mm", "must be a positive amplitude");
  if (settle_cycles < 0 || measured_cycles < 1) fail("cycles", "settle ≥ 0 and measured ≥ 1 cycles");
  const double period = 1.0 / frequency_hz;
  if (period < 8 * sys.dt())
    fail("frequency_hz", "needs at least 8 steps per cycle: " + short_num(frequency_hz) + " Hz is too fast for dt = " + short_num(sys.dt()) + " s");
  sys.set_base(amplitude_mm, frequency_hz);
  sys.run_for(settle_cycles * period);
  const auto n = static_cast<std::size_t>(std::llround(measured_cycles * period / sys.dt()));
  std::vector<double> t(n), x(n), y(n);
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  for (std::size_t k = 0; k < n; ++k) {
    sys.step();
    const SdofState& s = sys.state();
    t[k] = s.t, x[k] = s.x, y[k] = s.y;
    xmin = std::min(xmin, s.x), xmax = std::max(xmax, s.x), ymin = std::min(ymin, s.y), ymax = std::max(ymax, s.y);
  }
  const SineFit fx = fit_sine(t, x, frequency_hz), fy = fit_sine(t, y, frequency_hz);
  SteadyResponse r;
  r.frequency_hz = frequency_hz;
  r.base_amplitude_mm = fy.amplitude;
  r.mass_amplitude_mm = fx.amplitude;
  r.ratio = fy.amplitude > 0 ? fx.amplitude / fy.amplitude : 0;
  r.phase_rad = std::remainder(fx.phase_rad - fy.phase_rad, 2 * std::numbers::pi);
  r.peak_to_peak_ratio = ymax > ymin ? (xmax - xmin) / (ymax - ymin) : 0;
  return r;
}

double linear_transmissibility(double r, double zeta) noexcept {
  const double a = 2 * zeta * r;
  return std::sqrt((1 + a * a) / ((1 - r * r) * (1 - r * r) + a * a));
}

double max_stiffness(const EverettTable& table) noexcept {
  const Grid& g = table.grid();
  const double h = g.step();
  double k = 0;
  for (int i = 1; i <= g.n; ++i)
    for (int j = 0; j <= i; ++j) {
      if (j < i) k = std::max(k, std::fabs(table.node_value(i, j) - table.node_value(i - 1, j)) / h);
      if (j > 0) k = std::max(k, std::fabs(table.node_value(i, j) - table.node_value(i, j - 1)) / h);
    }
  return k > 0 ? k : 1e-9;
}

}  // namespace hystlab::models
