#include "hystlab/models/fot_design.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace hystlab::models {
namespace {

// One band [lo, lo + h] of the grid and what the table gets wrong inside it, per node of its
// midline: the curvature terms scale as h⁴, σ² halves with every row added.
struct Band {
  double lo = 0.0, h = 0.0;
  double curve_alpha = 0.0, curve_beta = 0.0;  // mean (∂²F/∂α² / 8)², (∂²F/∂β² / 8)² (N²/mm⁴)
  double sigma2 = 0.0;                         // mean σ² of its cells (N²)
  [[nodiscard]] double mse() const noexcept { return std::pow(h, 4) * (curve_alpha + curve_beta) + sigma2; }
  [[nodiscard]] Band half(double from) const noexcept { return Band{from, h / 2, curve_alpha, curve_beta, sigma2 / 2}; }
  // Area-weighted squared error removed by splitting it in two.
  [[nodiscard]] double gain() const noexcept { return h * (mse() - half(lo).mse()); }
};

// f'' from three points (divided differences).
double second(double x0, double f0, double x1, double f1, double x2, double f2) { return 2.0 * ((f2 - f1) / (x2 - x1) - (f1 - f0) / (x1 - x0)) / (x2 - x0); }

// The larger of the two centred estimates either side of band k along one direction: `at(m)` is
// F on line m (a row or a column), `valid(m)` whether the line reaches the node.
template <class At, class Valid>
double curvature(const Grid& g, int k, At at, Valid valid) {
  double worst = 0.0;
  for (int c : {k, k + 1})  // centred on node k (lines k-1, k, k+1) and on node k+1
    if (c - 1 >= 0 && c + 1 <= g.n && valid(c - 1) && valid(c) && valid(c + 1))
      worst = std::max(worst, std::fabs(second(g.node(c - 1), at(c - 1), g.node(c), at(c), g.node(c + 1), at(c + 1))));
  return worst;
}

Band band_of(const EverettTable& t, std::span<const double> sigma, int k) {
  const Grid& g = t.grid();
  Band b{g.node(k), g.node(k + 1) - g.node(k)};
  int count = 0;
  // Along α: across rows k and k+1, at every β node both reach (j <= k).
  for (int j = 0; j <= k; ++j, ++count) {
    const double d2 = curvature(
        g, k, [&](int i) { return t.node_value(i, j); }, [&](int i) { return j <= i; });
    b.curve_alpha += (d2 / 8) * (d2 / 8);
  }
  // Along β: across columns k and k+1, at every α node both reach (i >= k + 1).
  for (int i = k + 1; i <= g.n; ++i, ++count) {
    const double d2 = curvature(
        g, k, [&](int j) { return t.node_value(i, j); }, [&](int j) { return j <= i; });
    b.curve_beta += (d2 / 8) * (d2 / 8);
  }
  b.curve_alpha /= std::max(1, count);
  b.curve_beta /= std::max(1, count);
  if (!sigma.empty()) {  // the band's cells: its row (p = k+1) and its column (q = k+1)
    double s2 = 0.0;
    int cells = 0;
    for (int q = 1; q <= k + 1; ++q, ++cells) s2 += sigma[Grid::cell_index(k + 1, q)] * sigma[Grid::cell_index(k + 1, q)];
    for (int p = k + 2; p <= g.n; ++p, ++cells) s2 += sigma[Grid::cell_index(p, k + 1)] * sigma[Grid::cell_index(p, k + 1)];
    b.sigma2 = s2 / std::max(1, cells);
  }
  return b;
}

// The estimated RMS error over the range: every band's, plus the noise no row removes.
double rms(const std::vector<Band>& bands, double range, double noise) {
  double s = 0.0;
  for (const Band& b : bands) s += b.h * b.mse();
  return std::sqrt(s / range + noise * noise);
}

std::string why(const Band& b) {
  const double a = std::pow(b.h, 4) * b.curve_alpha, c = std::pow(b.h, 4) * b.curve_beta;
  char buf[160];
  if (b.sigma2 >= a && b.sigma2 >= c)
    std::snprintf(buf, sizeof buf, "the fit's uncertainty of the cells between %.3g and %.3g mm (σ %.3g N)", b.lo, b.lo + b.h, std::sqrt(b.sigma2));
  else
    std::snprintf(buf, sizeof buf, "the surface bends %s between %.3g and %.3g mm (interpolation error %.3g N)",
                  a >= c ? "along the rows" : "along the descents", b.lo, b.lo + b.h, std::sqrt(std::max(a, c)));
  return buf;
}

void validate(const EverettTable& t, std::span<const double> sigma, const DesignOptions& o) {
  if (!(o.ramp_mm_s > 0.0) || !std::isfinite(o.ramp_mm_s)) throw std::invalid_argument("design: ramp_mm_s must be a rate above 0 mm/s");
  if (!(o.settle_s >= 0.0) || !std::isfinite(o.settle_s)) throw std::invalid_argument("design: settle_s must be 0 or more seconds");
  if (!(o.target_rms_N >= 0.0) || !std::isfinite(o.target_rms_N)) throw std::invalid_argument("design: target_rms_N must be 0 (none) or more newtons");
  if (!(o.min_gain >= 0.0 && o.min_gain < 1.0)) throw std::invalid_argument("design: min_gain must be from 0 to below 1 (a share of the error left)");
  if (!(o.noise_N >= 0.0) || !std::isfinite(o.noise_N)) throw std::invalid_argument("design: noise_N must be 0 or more newtons");
  if (o.max_rows < 1) throw std::invalid_argument("design: max_rows must be at least 1");
  if (!sigma.empty() && sigma.size() != t.grid().cell_count())
    throw std::invalid_argument("design: the table's σ has " + std::to_string(sigma.size()) + " cells, its grid " + std::to_string(t.grid().cell_count()));
  const Grid& g = t.grid();
  const double cheapest = row_seconds(0.5 * (g.node(0) + g.node(1)) - g.lo, o.ramp_mm_s, o.settle_s);
  if (!(o.budget_s >= cheapest) || !std::isfinite(o.budget_s)) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "design: budget_s %.4g s is below one row (the cheapest, up to %.4g mm and back at %.4g mm/s, takes %.4g s)", o.budget_s,
                  0.5 * (g.node(0) + g.node(1)), o.ramp_mm_s, cheapest);
    throw std::invalid_argument(buf);
  }
}

}  // namespace

Design design_rows(const EverettTable& table, std::span<const double> cell_sigma, const DesignOptions& o) {
  validate(table, cell_sigma, o);
  const Grid& g = table.grid();
  const double range = g.hi - g.lo, min_band = o.min_band_mm > 0 ? o.min_band_mm : range / 1000;
  std::vector<Band> bands;
  for (int k = 0; k < g.n; ++k) bands.push_back(band_of(table, cell_sigma, k));
  auto cost = [&](const Band& b) { return row_seconds(b.lo + b.h / 2 - g.lo, o.ramp_mm_s, o.settle_s); };
  double scale = 1.0;  // rounding in the divided differences is not an error to chase
  for (double v : table.values()) scale = std::max(scale, std::fabs(v));
  const double negligible = 1e-9 * scale;
  Design d;
  d.rms_before_N = rms(bands, range, o.noise_N);
  double left = d.rms_before_N;
  d.stopped = "max_rows: " + std::to_string(o.max_rows) + " rows chosen";
  while (static_cast<int>(d.rows.size()) < o.max_rows) {
    if (o.target_rms_N > 0 && left <= o.target_rms_N) {
      d.stopped = "target: the estimated RMS error is at or below target_rms_N";
      break;
    }
    if (left <= o.noise_N + negligible) {
      d.stopped = "gain: the table's own estimated error is negligible (what is left is the noise)";
      break;
    }
    // The most squared error removed per second among the rows the budget still allows and that
    // each remove at least min_gain of the error left.
    const double total = left * left * range;
    const Band* best = nullptr;
    bool splittable = false, affordable = false;
    for (const Band& b : bands) {
      if (b.h / 2 < min_band) continue;
      splittable = true;
      if (d.seconds + cost(b) > o.budget_s) continue;
      affordable = true;
      if (b.gain() <= o.min_gain * total) continue;
      if (!best || b.gain() / cost(b) > best->gain() / cost(*best)) best = &b;
    }
    if (!best) {
      d.stopped = !splittable   ? "resolution: every band is at its narrowest"
                  : !affordable ? "budget: the next row would exceed budget_s"
                                : "gain: no row within the budget would remove min_gain of the error left";
      break;
    }
    const Band b = *best;
    DesignRow row{b.lo + b.h / 2, cost(b), std::sqrt(b.mse()), 0.0, why(b)};
    bands.erase(bands.begin() + (best - bands.data()));
    bands.push_back(b.half(b.lo));
    bands.push_back(b.half(b.lo + b.h / 2));
    left = rms(bands, range, o.noise_N);
    row.rms_after_N = left;
    d.seconds += row.seconds;
    d.rows.push_back(std::move(row));
  }
  for (int i = 0; i <= g.n; ++i) d.nodes.push_back(g.node(i));
  for (const DesignRow& r : d.rows) d.nodes.push_back(r.alpha_mm);
  std::sort(d.nodes.begin(), d.nodes.end());
  return d;
}

}  // namespace hystlab::models
