#include "hystlab/models/loop_figures.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "hystlab/models/accuracy.hpp"

namespace hystlab::models {
namespace {
struct Reversal {
  std::size_t index;
  bool peak;  // a maximum of the input; else a minimum
};

// Turning points with a dead band: an extreme counts once the input has come back from it by more
// than `band`. The first point is taken as a minimum or a maximum by where the input goes first.
std::vector<Reversal> reversals(std::span<const double> x, double band) {
  std::vector<Reversal> out;
  if (x.empty()) return out;
  std::size_t lo = 0, hi = 0, ext = 0;
  int dir = 0;  // +1 rising, -1 falling, 0 not yet known
  for (std::size_t k = 1; k < x.size(); ++k) {
    if (dir == 0) {  // until the input has moved by more than the band: the lowest and highest so far
      if (x[k] < x[lo]) lo = k;
      if (x[k] > x[hi]) hi = k;
      if (x[k] > x[lo] + band)
        out.push_back({lo, false}), dir = 1, ext = k;
      else if (x[k] < x[hi] - band)
        out.push_back({hi, true}), dir = -1, ext = k;
      continue;
    }
    if (dir > 0 ? x[k] > x[ext] : x[k] < x[ext]) {
      ext = k;
    } else if (dir > 0 ? x[k] < x[ext] - band : x[k] > x[ext] + band) {
      out.push_back({ext, dir > 0});
      dir = -dir;
      ext = k;
    }
  }
  if (dir != 0) out.push_back({ext, dir > 0});
  return out;
}

// Linear interpolation of f where x crosses `at` between samples a..b (inclusive), going up or down.
std::optional<double> crossing(std::span<const double> x, std::span<const double> f, std::size_t a, std::size_t b, double at, bool up) {
  for (std::size_t k = a; k < b; ++k) {
    const double x0 = x[k], x1 = x[k + 1];
    if (up ? (x0 <= at && at <= x1) : (x0 >= at && at >= x1)) {
      if (x1 == x0) return f[k];
      const double w = (at - x0) / (x1 - x0);
      return f[k] + w * (f[k + 1] - f[k]);
    }
  }
  return std::nullopt;
}

// Where the unloading branch dn0..dn1 first comes down to the start's force (1 % of the cycle's
// force range above it), interpolated, as a distance from the start's displacement.
double residual_of(std::span<const double> x, std::span<const double> f, const LoopFigures& L, std::size_t dn0, std::size_t dn1) {
  if (L.starts_at_max) return std::numeric_limits<double>::quiet_NaN();
  const double level = L.force_at_min_N + 0.01 * (L.peak_force_N - L.force_at_min_N);
  for (std::size_t k = dn0; k < dn1; ++k)
    if (f[k] > level && f[k + 1] <= level) {
      const double w = (f[k] - level) / (f[k] - f[k + 1]);
      return std::max(0.0, x[k] + w * (x[k + 1] - x[k]) - L.min_mm);
    }
  return 0.0;
}

std::optional<SmaTransitions> transformation_of(const LoopFigures& L) {
  if (!L.loading || !L.unloading || !L.loading->has_plateau() || !L.unloading->has_plateau()) return std::nullopt;
  SmaTransitions t;
  t.Ms = {L.loading->lower_mm, L.loading->lower_N};
  t.Mf = {L.loading->upper_mm, L.loading->upper_N};
  t.Af = {L.unloading->lower_mm, L.unloading->lower_N};
  t.As = {L.unloading->upper_mm, L.unloading->upper_N};
  return t;
}
}  // namespace

LoopFigures loop_figures(std::span<const double> x, std::span<const double> f, std::size_t begin, std::size_t turn, std::size_t end, const LoopOptions& o) {
  if (x.size() != f.size() || !(begin < turn && turn < end && end < x.size()))
    throw std::invalid_argument("loop_figures: the cycle's samples must satisfy begin < turn < end within the record");
  LoopFigures L;
  L.begin = begin;
  L.turn = turn;
  L.end = end;
  L.starts_at_max = x[begin] > x[turn];
  const std::size_t lo = L.starts_at_max ? turn : begin, hi = L.starts_at_max ? begin : turn;
  L.min_mm = x[lo];
  L.max_mm = x[hi];
  L.force_at_min_N = f[lo];
  L.force_at_max_N = f[hi];
  L.peak_force_N = *std::max_element(f.begin() + static_cast<std::ptrdiff_t>(begin), f.begin() + static_cast<std::ptrdiff_t>(end) + 1);
  // Back at the start's displacement, interpolated on the last step.
  L.return_N = crossing(x, f, end - 1, end, x[begin], L.starts_at_max).value_or(f[end]);
  const std::size_t n = end - begin + 1;
  L.energy_Nmm = path_work(x.subspan(begin, n), f.subspan(begin, n)) + 0.5 * (f[end] + f[begin]) * (x[begin] - x[end]);
  const double span = L.max_mm - L.min_mm;
  L.secant_stiffness_N_mm = (L.force_at_max_N - L.force_at_min_N) / span;
  L.strain_energy_Nmm = 0.5 * L.secant_stiffness_N_mm * (span / 2) * (span / 2);
  L.damping_ratio = L.strain_energy_Nmm > 0 ? L.energy_Nmm / (4 * std::numbers::pi * L.strain_energy_Nmm) : 0.0;
  // The loading branch runs up from the minimum, the unloading branch down from the maximum.
  const std::size_t up0 = L.starts_at_max ? turn : begin, up1 = L.starts_at_max ? end : turn;
  const std::size_t dn0 = L.starts_at_max ? begin : turn, dn1 = L.starts_at_max ? turn : end;
  for (const double at : o.plateau_at_mm) {
    if (!(at >= L.min_mm && at <= L.max_mm)) continue;
    const auto up = crossing(x, f, up0, up1, at, true), down = crossing(x, f, dn0, dn1, at, false);
    if (up && down) L.plateaus.push_back({at, *up, *down});
  }
  L.residual_mm = residual_of(x, f, L, dn0, dn1);
  L.loading = fit_branch_knees(x.subspan(up0, up1 - up0 + 1), f.subspan(up0, up1 - up0 + 1));
  L.unloading = fit_branch_knees(x.subspan(dn0, dn1 - dn0 + 1), f.subspan(dn0, dn1 - dn0 + 1));
  L.transformation = transformation_of(L);
  return L;
}

namespace {
struct Cycle {
  std::size_t begin, turn, end;
};

// Where the path from reversal `from` on first gets back to the displacement `level` (or the
// sample nearest it before `to`, when it stops within the band of it).
std::size_t return_index(std::span<const double> x, std::size_t from, std::size_t to, double level, bool downward) {
  for (std::size_t k = from; k <= to; ++k)
    if (downward ? x[k] <= level : x[k] >= level) return k;
  return to;
}

// Rainflow counting of the reversals (ASTM E1049's four-point rule: (B, C) is a closed cycle when
// its range is within those of its neighbours (A, B) and (C, D)), the band as tolerance, with one
// addition for a load frame: a minimum A, a maximum B and a return C to A's level close (A, B) as a
// load-unload cycle from A, before the four-point rule would close (B, C) from the maximum. So a
// record of major loops from δmin gives load-unload cycles from δmin (with plain rainflow, every
// loop but the last would run from δmax down and back), and an FOT record one cycle per row.
std::vector<Cycle> rainflow(std::span<const double> x, const std::vector<Reversal>& r, double band) {
  std::vector<Cycle> out;
  std::vector<Reversal> st;
  auto range = [&](const Reversal& a, const Reversal& b) { return std::fabs(x[a.index] - x[b.index]); };
  auto close = [&](std::size_t i) {  // (st[i], st[i+1]) closes on the way to st[i+2]
    const Reversal &B = st[i], &C = st[i + 1], &D = st[i + 2];
    out.push_back({B.index, C.index, return_index(x, C.index, D.index, x[B.index], !B.peak)});
    st.erase(st.begin() + static_cast<std::ptrdiff_t>(i), st.begin() + static_cast<std::ptrdiff_t>(i) + 2);
  };
  for (const Reversal& rv : r) {
    st.push_back(rv);
    for (bool again = true; again;) {
      again = false;
      const std::size_t m = st.size();
      if (m >= 3 && !st[m - 3].peak && range(st[m - 2], st[m - 1]) + band >= range(st[m - 3], st[m - 2])) {
        close(m - 3);
        again = true;
      } else if (m >= 4) {
        const double bc = range(st[m - 3], st[m - 2]);
        if (bc <= range(st[m - 4], st[m - 3]) + band && bc <= range(st[m - 2], st[m - 1]) + band) {
          close(m - 3);
          again = true;
        }
      }
    }
  }
  return out;
}

// The samples of a cycle without those of the cycles nested in it (as rainflow counts them: an
// inner loop's area is its own, not its host's).
void gather(std::span<const double> x, std::span<const double> f, const Cycle& c, const std::vector<Cycle>& inner, std::vector<double>& gx,
            std::vector<double>& gf, std::size_t& turn_at) {
  gx.clear();
  gf.clear();
  std::size_t k = c.begin;
  while (k <= c.end) {
    if (k == c.turn) turn_at = gx.size();
    gx.push_back(x[k]);
    gf.push_back(f[k]);
    // An inner loop's samples after its start, up to its return (kept: both are on the host's path).
    std::size_t next = k + 1;
    for (const Cycle& i : inner)
      if (i.begin == k && i.end <= c.end && i.end > next && !(i.begin == c.begin && i.end == c.end)) next = i.end;
    if (c.turn > k && c.turn < next) turn_at = gx.size() - 1;  // the host turns inside it: its start stands for the turn
    k = next;
  }
}
}  // namespace

std::vector<LoopFigures> find_loops(std::span<const double> x, std::span<const double> f, const LoopOptions& o) {
  if (x.size() != f.size()) throw std::invalid_argument("loops: displacement and force differ in length");
  for (std::size_t k = 0; k < x.size(); ++k)
    if (!std::isfinite(x[k]) || !std::isfinite(f[k])) throw std::invalid_argument("loops: sample " + std::to_string(k) + " is not a finite number");
  if (!(o.reversal_fraction > 0 && o.reversal_fraction < 0.5) || !(o.min_span_fraction >= 0 && o.min_span_fraction < 1))
    throw std::invalid_argument("loops: reversal_fraction must be in (0, 0.5) and min_span_fraction in [0, 1)");
  std::vector<LoopFigures> out;
  if (x.size() < 3) return out;
  const auto [mn, mx] = std::minmax_element(x.begin(), x.end());
  const double range = *mx - *mn;
  if (!(range > 0)) return out;
  const double band = o.reversal_fraction * range, min_span = o.min_span_fraction * range;
  std::vector<Cycle> cycles = rainflow(x, reversals(x, band), band);
  std::sort(cycles.begin(), cycles.end(), [](const Cycle& a, const Cycle& b) { return a.end < b.end || (a.end == b.end && a.begin > b.begin); });
  std::vector<double> gx, gf;
  for (std::size_t c = 0; c < cycles.size(); ++c) {
    const Cycle& cy = cycles[c];
    if (std::fabs(x[cy.turn] - x[cy.begin]) < min_span || !(cy.begin < cy.turn && cy.turn < cy.end)) continue;
    std::size_t turn_at = 0;
    gather(x, f, cy, std::vector<Cycle>(cycles.begin(), cycles.begin() + static_cast<std::ptrdiff_t>(c)), gx, gf, turn_at);
    if (!(turn_at > 0 && turn_at + 1 < gx.size())) continue;
    LoopFigures L = loop_figures(gx, gf, 0, turn_at, gx.size() - 1, o);
    L.begin = cy.begin;  // indices of the record, not of the gathered samples
    L.turn = cy.turn;
    L.end = cy.end;
    out.push_back(std::move(L));
  }
  return out;
}

std::optional<SmaTransitions> loop_transformation(std::span<const double> x, std::span<const double> f) {
  if (x.size() != f.size() || x.size() < 3) return std::nullopt;
  const std::size_t top = static_cast<std::size_t>(std::max_element(x.begin(), x.end()) - x.begin());
  if (top == 0 || top + 1 >= x.size()) return std::nullopt;
  LoopFigures L;
  L.loading = fit_branch_knees(x.subspan(0, top + 1), f.subspan(0, top + 1));
  L.unloading = fit_branch_knees(x.subspan(top), f.subspan(top));
  return transformation_of(L);
}

}  // namespace hystlab::models
