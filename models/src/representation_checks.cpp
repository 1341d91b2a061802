#include "hystlab/models/representation_checks.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hystlab::models {
namespace {

struct Turning {
  std::size_t index;
  bool is_max;
};

// A closed minor loop: first branch from index a to b, return branch from b to the crossing c.
struct Loop {
  double lo, hi;
  std::vector<double> rise, fall;  // force increments along each branch at equally spaced inputs
};

// Force on the monotone stretch [from, to] where the input first reaches u (linear interpolation).
double force_at(std::span<const double> x, std::span<const double> f, std::size_t from, std::size_t to, double u) {
  const bool up = x[to] >= x[from];
  for (std::size_t k = from + 1; k <= to; ++k) {
    const bool crossed = up ? x[k] >= u : x[k] <= u;
    if (crossed) {
      const double dx = x[k] - x[k - 1];
      const double s = dx != 0.0 ? std::clamp((u - x[k - 1]) / dx, 0.0, 1.0) : 1.0;
      return f[k - 1] + s * (f[k] - f[k - 1]);
    }
  }
  return f[to];
}

std::vector<double> branch_shape(std::span<const double> x, std::span<const double> f, std::size_t from, std::size_t to, double lo, double hi, int points) {
  std::vector<double> s(static_cast<std::size_t>(points) + 1);
  const bool up = x[to] >= x[from];
  const double f0 = force_at(x, f, from, to, up ? lo : hi);
  for (int k = 0; k <= points; ++k) {
    const double u = lo + (hi - lo) * k / points;
    s[static_cast<std::size_t>(k)] = force_at(x, f, from, to, u) - f0;
  }
  return s;
}

}  // namespace

std::vector<std::size_t> find_reversals(std::span<const double> x, double dead_band) {
  std::vector<std::size_t> out;
  if (x.size() < 2) return out;
  int dir = 0;  // 0 unknown, +1 rising, -1 falling
  std::size_t extreme = 0;
  for (std::size_t k = 1; k < x.size(); ++k) {
    if (dir == 0) {
      if (std::fabs(x[k] - x[0]) > dead_band) {
        dir = x[k] > x[0] ? 1 : -1;
        extreme = k;
      } else if ((x[k] > x[extreme]) == (x[extreme] >= x[0])) {
        extreme = k;
      }
      continue;
    }
    if ((dir > 0 && x[k] >= x[extreme]) || (dir < 0 && x[k] <= x[extreme])) {
      extreme = k;
    } else if (std::fabs(x[k] - x[extreme]) > dead_band) {
      out.push_back(extreme);
      dir = -dir;
      extreme = k;
    }
  }
  return out;
}

RepresentationReport check_representation(std::span<const double> x, std::span<const double> f, const RepresentationOptions& opt) {
  if (x.size() != f.size()) throw std::invalid_argument("check: displacement and force differ in length");
  for (std::size_t k = 0; k < x.size(); ++k)
    if (!std::isfinite(x[k]) || !std::isfinite(f[k])) throw std::invalid_argument("check: sample " + std::to_string(k) + " is not a finite number");
  RepresentationReport r;
  if (x.size() < 3) return r;
  const auto [xmin, xmax] = std::minmax_element(x.begin(), x.end());
  const auto [fmin, fmax] = std::minmax_element(f.begin(), f.end());
  const double xr = *xmax - *xmin;
  r.force_range = *fmax - *fmin;
  const double band = opt.dead_band >= 0 ? opt.dead_band : 0.005 * xr;
  const double ext_tol = opt.extremum_tolerance >= 0 ? opt.extremum_tolerance : 0.01 * xr;
  const std::vector<std::size_t> rev = find_reversals(x, band);
  r.reversals = rev.size();

  std::vector<Turning> stack{{0, x.size() > 1 && x[1] < x[0]}};
  std::vector<Loop> loops;
  double ss = 0.0;
  std::size_t next = 0;
  for (std::size_t k = 1; k < x.size(); ++k) {
    const bool rising = !stack.back().is_max;
    // Wipe-out: the input passes the turning point two below the top (same kind as the move's target).
    while (stack.size() >= 3) {
      const Turning& target = stack[stack.size() - 2];
      const double level = x[target.index];
      if (rising ? x[k] < level : x[k] > level) break;
      const Turning inner = stack.back();
      const double on_return = force_at(x, f, inner.index, k, level);
      const double dev = on_return - f[target.index];
      ss += dev * dev;
      ++r.wiping_out.events;
      r.wiping_out.max_deviation = std::max(r.wiping_out.max_deviation, std::fabs(dev));
      const double lo = std::min(level, x[inner.index]), hi = std::max(level, x[inner.index]);
      Loop loop{lo, hi, {}, {}};
      auto first = branch_shape(x, f, target.index, inner.index, lo, hi, opt.branch_points);
      auto second = branch_shape(x, f, inner.index, k, lo, hi, opt.branch_points);
      loop.rise = rising ? std::move(second) : std::move(first);
      loop.fall = rising ? std::move(first) : std::move(second);
      loops.push_back(std::move(loop));
      stack.resize(stack.size() - 2);
    }
    if (next < rev.size() && rev[next] == k) {
      stack.push_back(Turning{k, !stack.back().is_max});
      ++next;
    }
  }
  if (r.wiping_out.events) r.wiping_out.rms_deviation = std::sqrt(ss / static_cast<double>(r.wiping_out.events));
  r.wiping_out.max_deviation_norm = r.force_range > 0 ? r.wiping_out.max_deviation / r.force_range : 0.0;

  r.congruency.loops = loops.size();
  double css = 0.0;
  std::size_t cn = 0;
  for (std::size_t a = 0; a < loops.size(); ++a)
    for (std::size_t b = a + 1; b < loops.size(); ++b) {
      if (std::fabs(loops[a].lo - loops[b].lo) > ext_tol || std::fabs(loops[a].hi - loops[b].hi) > ext_tol) continue;
      ++r.congruency.compared_pairs;
      for (std::size_t k = 0; k < loops[a].rise.size(); ++k) {
        for (const double d : {loops[a].rise[k] - loops[b].rise[k], loops[a].fall[k] - loops[b].fall[k]}) {
          css += d * d;
          ++cn;
          r.congruency.max_deviation = std::max(r.congruency.max_deviation, std::fabs(d));
        }
      }
    }
  if (cn) r.congruency.rms_deviation = std::sqrt(css / static_cast<double>(cn));
  r.congruency.max_deviation_norm = r.force_range > 0 ? r.congruency.max_deviation / r.force_range : 0.0;
  return r;
}

}  // namespace hystlab::models
