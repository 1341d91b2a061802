#include "adaptive_rows.hpp"

#include <algorithm>

namespace hystlab::daemon {

AdaptiveRows::AdaptiveRows(const domain::Plan& plan) : plan_(plan) {
  options_.ramp_mm_s = plan.ramp_rate_mm_s;
  options_.settle_s = 2.0 * plan.dwell_s + domain::kRowSettle_s;  // domain::row_seconds's model
  options_.budget_s = plan.design.budget_s;
  options_.target_rms_N = plan.design.target_rms_N;
  options_.min_gain = plan.design.min_gain;
}

bool AdaptiveRows::stopped_before(const models::OnlineTableBuilder& fine) const {
  const std::vector<int> rows = models::measured_rows(fine);
  for (int i = 1; i <= plan_.subdivisions; ++i)  // a coarse row missing: the design has not begun
    if (std::find(rows.begin(), rows.end(), i * (plan_.design.finest_subdivisions / plan_.subdivisions)) == rows.end()) return false;
  return !models::next_row(fine, options_).row;
}

std::optional<std::vector<Segment>> AdaptiveRows::next(const models::OnlineTableBuilder& fine, const RunSeries& series, domain::DesignEvent& event) {
  if (over_) return std::nullopt;
  if (!noise_) {
    // The last 20,000 samples (20 s at 1 kHz: a descent or more), copied once.
    constexpr std::size_t kNoiseSamples = 20'000;
    const std::size_t e = series.size(), b = e > kNoiseSamples ? e - kNoiseSamples : 0;
    Columns c;
    if (e > b) series.copy(b, e, c);
    noise_ = models::force_noise(c.f);
  }
  options_.noise_N = *noise_;
  const models::AdaptiveStep st = models::next_row(fine, options_);
  event = {};
  event.rows = static_cast<std::int64_t>(st.nodes_mm.size()) - 1;
  event.estimated_rms_N = st.estimated_rms_N, event.noise_N = *noise_, event.spent_s = st.spent_s, event.budget_s = options_.budget_s;
  event.target_rms_N = options_.target_rms_N;
  event.nodes_mm = st.nodes_mm;
  if (!st.row) {
    over_ = true;
    event.stopped = st.stopped;
    return std::nullopt;
  }
  if (std::find(chosen_.begin(), chosen_.end(), *st.row) != chosen_.end()) {
    over_ = true;
    event.stopped = "the row to " + std::to_string(st.alpha_mm) + " mm was driven and could not be measured whole (a node missing after its retakes)";
    return std::nullopt;
  }
  event.alpha_mm = st.alpha_mm, event.next_s = st.next_s, event.why = st.why;
  chosen_.push_back(*st.row);
  return std::vector<Segment>{{st.alpha_mm, plan_.ramp_rate_mm_s, plan_.dwell_s, SegmentKind::rise, *st.row},
                              {plan_.lo_mm, plan_.ramp_rate_mm_s, plan_.dwell_s, SegmentKind::descent, *st.row}};
}

}  // namespace hystlab::daemon
