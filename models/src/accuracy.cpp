#include "hystlab/models/accuracy.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hystlab::models {
namespace {
struct Accumulator {
  double ss = 0.0, mx = 0.0;
  std::size_t n = 0;
  void add(double e) {
    ss += e * e;
    mx = std::max(mx, std::fabs(e));
    ++n;
  }
  ErrorStats stats(double range) const {
    ErrorStats s;
    s.count = n;
    s.rms = n ? std::sqrt(ss / static_cast<double>(n)) : 0.0;
    s.max_abs = mx;
    s.rms_norm = range > 0 ? s.rms / range : 0.0;
    s.max_norm = range > 0 ? s.max_abs / range : 0.0;
    return s;
  }
};
}  // namespace

double path_work(std::span<const double> input, std::span<const double> force) noexcept {
  double w = 0.0;
  for (std::size_t k = 1; k < input.size() && k < force.size(); ++k) w += 0.5 * (force[k] + force[k - 1]) * (input[k] - input[k - 1]);
  return w;
}

AccuracyReport compare(std::span<const double> input, std::span<const double> reference, std::span<const double> model) {
  if (input.size() != reference.size() || input.size() != model.size())
    throw std::invalid_argument("compare: input, reference and model series differ in length");
  AccuracyReport r;
  if (input.empty()) return r;
  const auto [mn, mx] = std::minmax_element(reference.begin(), reference.end());
  r.reference_range = *mx - *mn;
  Accumulator all, up, down;
  bool rising = true;
  for (std::size_t k = 0; k < input.size(); ++k) {
    if (k > 0 && input[k] != input[k - 1]) rising = input[k] > input[k - 1];
    const double e = model[k] - reference[k];
    all.add(e);
    (rising ? up : down).add(e);
  }
  r.overall = all.stats(r.reference_range);
  r.ascending = up.stats(r.reference_range);
  r.descending = down.stats(r.reference_range);
  const auto [imin, imax] = std::minmax_element(input.begin(), input.end());
  if (std::fabs(input.back() - input.front()) <= 1e-9 * (1.0 + *imax - *imin) && input.size() > 2) {
    const double er = path_work(input, reference), em = path_work(input, model);
    r.energy_reference = er;
    r.energy_model = em;
    if (er != 0.0) r.energy_rel_error = (em - er) / std::fabs(er);
  }
  return r;
}

}  // namespace hystlab::models
