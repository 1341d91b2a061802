#include "hystlab/models/adaptive_fot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace hystlab::models {

std::vector<int> measured_rows(const OnlineTableBuilder& fine) {
  std::vector<int> rows{0};
  for (int i = 1; i <= fine.grid().n; ++i) {
    bool whole = true;
    for (int j = 0; j < i && whole; ++j) whole = fine.identified(i, j);
    if (whole) rows.push_back(i);
  }
  return rows;
}

std::optional<OnlineTableBuilder> rows_builder(const OnlineTableBuilder& fine) {
  const std::vector<int> rows = measured_rows(fine);
  if (rows.back() != fine.grid().n) return std::nullopt;
  return fine.restricted(rows);
}

AdaptiveStep next_row(const OnlineTableBuilder& fine, const AdaptiveOptions& o) {
  AdaptiveStep st;
  const Grid& g = fine.grid();
  const std::vector<int> rows = measured_rows(fine);
  for (int i : rows) {
    st.nodes_mm.push_back(g.node(i));
    if (i > 0) st.spent_s += row_seconds(g.node(i) - g.lo, o.ramp_mm_s, o.settle_s);
  }
  if (rows.back() != g.n) {
    st.stopped = "the top row is not measured yet";
    return st;
  }
  const EverettTable table = fine.restricted(rows).table();
  char buf[200];
  if (o.target_rms_N > 0 && o.target_rms_N <= o.noise_N) {
    std::snprintf(buf, sizeof buf, "target: target_rms_N %.3g N is at or below the force noise measured (%.3g N): no row can reach it", o.target_rms_N,
                  o.noise_N);
    st.stopped = buf;
  }
  DesignOptions d;
  d.ramp_mm_s = o.ramp_mm_s;
  d.settle_s = o.settle_s;
  d.target_rms_N = o.target_rms_N;
  d.min_gain = o.min_gain;
  d.noise_N = o.noise_N;
  d.max_rows = 1;
  d.min_band_mm = 0.999 * g.step();  // a band one fine step wide has no fine node inside
  // The cheapest row the table allows (its lowest band halved): below it, the budget is spent.
  const Grid& tg = table.grid();
  const double cheapest = row_seconds(0.5 * (tg.node(0) + tg.node(1)) - g.lo, o.ramp_mm_s, o.settle_s);
  d.budget_s = std::max(o.budget_s - st.spent_s, cheapest);
  const Design plan = design_rows(table, {}, d);
  st.estimated_rms_N = plan.rms_before_N;
  if (!st.stopped.empty()) return st;
  if (o.budget_s - st.spent_s < cheapest) {
    std::snprintf(buf, sizeof buf, "budget: %.4g s of budget_s %.4g s left, below the cheapest row (%.4g s)", o.budget_s - st.spent_s, o.budget_s, cheapest);
    st.stopped = buf;
    return st;
  }
  if (plan.rows.empty()) {
    st.stopped = plan.stopped;
    return st;
  }
  st.alpha_mm = plan.rows.front().alpha_mm;
  st.next_s = plan.rows.front().seconds;
  st.why = plan.rows.front().why;
  const int i = g.node_near(st.alpha_mm, 0.25 * g.step());
  if (i < 1) {  // cannot happen: a band wider than a fine step halves onto a fine node
    st.stopped = "resolution: the next row's top is not on the finest grid";
    return st;
  }
  st.row = i;
  st.alpha_mm = g.node(i);
  return st;
}

double force_noise(std::span<const double> f) {
  if (f.size() < 3) return 0.0;
  std::vector<double> d2;
  d2.reserve(f.size() - 2);
  for (std::size_t k = 1; k + 1 < f.size(); ++k) {
    const double d = f[k + 1] - 2.0 * f[k] + f[k - 1];
    d2.push_back(d * d);
  }
  auto mid = d2.begin() + static_cast<std::ptrdiff_t>(d2.size() / 2);
  std::nth_element(d2.begin(), mid, d2.end());
  return std::sqrt(*mid / 0.4549 / 6.0);
}

}  // namespace hystlab::models
