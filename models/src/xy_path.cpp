#include "hystlab/models/xy_path.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace hystlab::models {
namespace {
struct Span2 {
  double x = 1, y = 1;
};

Span2 ranges(std::span<const float> x, std::span<const float> y) {
  const auto [x0, x1] = std::minmax_element(x.begin(), x.end());
  const auto [y0, y1] = std::minmax_element(y.begin(), y.end());
  const double rx = static_cast<double>(*x1) - static_cast<double>(*x0), ry = static_cast<double>(*y1) - static_cast<double>(*y0);
  return {rx > 0 ? rx : 1.0, ry > 0 ? ry : 1.0};
}

// Walks the path, calling keep(k) whenever the arc length since the last kept point reaches step
// (step <= 0: only measures). Returns the total arc length. Motion below quantum from the last
// anchor is not counted (noise).
template <class Keep>
double walk(std::span<const float> x, std::span<const float> y, Span2 r, double quantum, double step, Keep keep) {
  // Squared distances, scales as factors: most samples of a slow ramp are under the quantum and
  // cost a few multiplications (std::hypot on every sample made 10^7 samples take 270 ms).
  const double sx = 1.0 / r.x, sy = 1.0 / r.y, q2 = quantum * quantum;
  double total = 0, acc = 0, ax = x[0], ay = y[0];
  for (std::size_t k = 1; k < x.size(); ++k) {
    const double dx = (x[k] - ax) * sx, dy = (y[k] - ay) * sy, d2 = dx * dx + dy * dy;
    if (d2 < q2) continue;
    const double d = std::sqrt(d2);
    total += d, acc += d, ax = x[k], ay = y[k];
    if (step > 0 && acc >= step) keep(k), acc = 0;
  }
  return total;
}
}  // namespace

std::vector<std::size_t> reversals_of(std::span<const float> x, double threshold) {
  std::vector<std::size_t> out;
  if (x.size() < 3) return out;
  int dir = 0;
  std::size_t ext = 0, lo = 0, hi = 0;
  for (std::size_t k = 1; k < x.size(); ++k) {
    const double v = x[k];
    if (dir == 0) {  // the first move decides the direction
      if (v > x[hi]) hi = k;
      if (v < x[lo]) lo = k;
      if (v - x[lo] > threshold)
        dir = 1, ext = k;
      else if (x[hi] - v > threshold)
        dir = -1, ext = k;
      continue;
    }
    if (dir > 0 ? v >= x[ext] : v <= x[ext]) {
      ext = k;
    } else if (std::abs(x[ext] - v) > threshold) {
      out.push_back(ext);
      dir = -dir, ext = k;
    }
  }
  return out;
}

PathReduction reduce_path(std::span<const float> x, std::span<const float> y, std::size_t budget, double reversal_fraction) {
  PathReduction r;
  const std::size_t n = std::min(x.size(), y.size());
  if (n == 0) return r;
  x = x.first(n), y = y.first(n);
  const Span2 span = ranges(x, y);
  const std::vector<std::size_t> turns = reversals_of(x, reversal_fraction * span.x);
  r.reversals = turns.size();
  if (n <= std::max<std::size_t>(budget, 2)) {
    r.index.resize(n);
    for (std::size_t k = 0; k < n; ++k) r.index[k] = k;
    return r;
  }
  const double quantum = 1e-3;  // 0.1 % of the plot's range: below a pixel at any plot size
  const double total = walk(x, y, span, quantum, 0.0, [](std::size_t) {});
  const std::size_t spare = budget > turns.size() + 2 ? budget - turns.size() - 2 : 0;
  std::vector<std::size_t> along;
  along.reserve(spare + 1);
  if (spare > 0 && total > 0) walk(x, y, span, quantum, total / static_cast<double>(spare), [&](std::size_t k) { along.push_back(k); });
  r.index.reserve(along.size() + turns.size() + 2);
  r.index.push_back(0);
  std::merge(along.begin(), along.end(), turns.begin(), turns.end(), std::back_inserter(r.index));
  r.index.push_back(n - 1);
  r.index.erase(std::unique(r.index.begin(), r.index.end()), r.index.end());
  return r;
}

}  // namespace hystlab::models
