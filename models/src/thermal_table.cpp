#include "hystlab/models/thermal_table.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <cstdio>

namespace hystlab::models {
namespace {
std::string degrees_text(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

// The model's first temperature: a number, clamped to the identified range of a checked table.
double first_temperature(const ThermalTable& t, double T) {
  check_thermal_table(t);
  if (!std::isfinite(T)) throw std::invalid_argument("thermal model: the temperature is not a finite number");
  return std::clamp(T, t.temperatures_C.front(), t.temperatures_C.back());
}

// The neighbours of T (clamped to the range) and T's weight on the upper one.
void neighbours(const ThermalTable& t, double T, std::size_t& lo, double& w) noexcept {
  const std::vector<double>& ts = t.temperatures_C;
  T = std::clamp(T, ts.front(), ts.back());
  lo = static_cast<std::size_t>(std::upper_bound(ts.begin(), ts.end(), T) - ts.begin());
  lo = lo == 0 ? 0 : std::min(lo - 1, ts.size() - 2);
  w = (T - ts[lo]) / (ts[lo + 1] - ts[lo]);
}
}  // namespace

void check_thermal_table(const ThermalTable& t) {
  if (t.temperatures_C.size() != t.tables.size())
    throw std::invalid_argument("thermal table: " + std::to_string(t.temperatures_C.size()) + " temperatures for " + std::to_string(t.tables.size()) +
                                " tables");
  if (t.tables.size() < 2) throw std::invalid_argument("thermal table: tables at two temperatures at least are needed, got " + std::to_string(t.tables.size()));
  for (std::size_t k = 0; k < t.tables.size(); ++k) {
    const double T = t.temperatures_C[k];
    if (!t.tables[k]) throw std::invalid_argument("thermal table: no table at temperature " + std::to_string(k + 1));
    if (!std::isfinite(T)) throw std::invalid_argument("thermal table: temperature " + std::to_string(k + 1) + " is not a finite number");
    if (k > 0 && !(T > t.temperatures_C[k - 1]))
      throw std::invalid_argument("thermal table: the temperatures must increase: " + degrees_text(T) + " °C follows " + degrees_text(t.temperatures_C[k - 1]) +
                                  " °C");
    if (k > 0 && !t.tables[k]->grid().same_nodes(t.tables[0]->grid()))
      throw std::invalid_argument("thermal table: the table at " + degrees_text(T) + " °C is not on the nodes of the table at " +
                                  degrees_text(t.temperatures_C[0]) + " °C (identify every temperature on one grid)");
  }
}

ThermalTable make_thermal_table(std::vector<double> temperatures_C, std::vector<EverettTable> tables) {
  ThermalTable out;
  for (EverettTable& e : tables) out.tables.push_back(std::make_shared<const EverettTable>(std::move(e)));
  out.temperatures_C = std::move(temperatures_C);
  check_thermal_table(out);
  return out;
}

EverettTable table_at(const ThermalTable& t, double temperature_C) {
  check_thermal_table(t);
  if (std::isnan(temperature_C)) throw std::invalid_argument("thermal table: the temperature is not a number");
  std::size_t lo = 0;
  double w = 0;
  neighbours(t, temperature_C, lo, w);
  EverettTable out(t.tables[lo]->grid());
  out.assign_blend(*t.tables[lo], *t.tables[lo + 1], w);
  return out;
}

ThermalPreisachModel::ThermalPreisachModel(ThermalTable table, double temperature_C, PreisachOptions options, double tolerance_K)
    : thermal_(std::move(table)),
      tolerance_K_(tolerance_K),
      temperature_(first_temperature(thermal_, temperature_C)),
      blended_for_(temperature_),
      now_(std::make_shared<EverettTable>(table_at(thermal_, temperature_))),
      next_(std::make_shared<EverettTable>(*now_)),
      inner_(now_, options) {
  if (!(tolerance_K >= 0) || !std::isfinite(tolerance_K)) throw std::invalid_argument("thermal model: the tolerance must be a finite number of kelvin >= 0");
  if (temperature_C != temperature_) ++t_saturations_;  // clamped to the identified range: counted
}

ThermalPreisachModel::ThermalPreisachModel(const ThermalPreisachModel& o)
    : thermal_(o.thermal_),
      tolerance_K_(o.tolerance_K_),
      temperature_(o.temperature_),
      blended_for_(o.blended_for_),
      t_saturations_(o.t_saturations_),
      reblends_(o.reblends_),
      now_(std::make_shared<EverettTable>(*o.now_)),
      next_(std::make_shared<EverettTable>(*o.next_)),
      inner_(o.inner_) {
  inner_.use_copy_of_table(now_);  // the same values: the same memory, read from its own table
}

std::unique_ptr<HysteresisModel> ThermalPreisachModel::clone() const { return std::make_unique<ThermalPreisachModel>(*this); }

void ThermalPreisachModel::retemper(double temperature_C) noexcept {
  const std::vector<double>& ts = thermal_.temperatures_C;
  if (std::isnan(temperature_C) || temperature_C < ts.front() || temperature_C > ts.back()) {
    ++t_saturations_;
    if (std::isnan(temperature_C)) return;  // the last temperature is kept
  }
  temperature_ = std::clamp(temperature_C, ts.front(), ts.back());
  if (std::fabs(temperature_ - blended_for_) <= tolerance_K_) return;
  std::size_t lo = 0;
  double w = 0;
  neighbours(thermal_, temperature_, lo, w);
  next_->assign_blend(*thermal_.tables[lo], *thermal_.tables[lo + 1], w);  // same grid: cannot throw
  inner_.replace_table_on_same_nodes(next_);                               // checked in make_thermal_table
  std::swap(now_, next_);
  blended_for_ = temperature_;
  ++reblends_;
}

}  // namespace hystlab::models
