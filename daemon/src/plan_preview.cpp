#include "hystlab/daemon/plan_preview.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "hystlab/daemon/sequencer.hpp"

namespace hystlab::daemon {
namespace {
PlanPreview preview_sine(const domain::Plan& p) {
  PlanPreview v;
  const double a = p.sine.max_amplitude_mm(), w = 2 * std::numbers::pi * p.sine.highest_hz();
  v.duration_s = domain::nominal_duration_s(p.sine);
  v.peak_speed_mm_s = w * a;
  v.peak_accel_m_s2 = w * w * a * 1e-3;
  v.nodes = domain::step_count(p.sine);
  return v;
}
}  // namespace

PlanPreview preview_plan(const domain::Plan& plan, models::HysteresisModel* model) {
  PlanPreview v;
  if (plan.kind == domain::CampaignKind::sine) {
    v = preview_sine(plan);
  } else {
    const std::vector<Segment> segs = plan.kind == domain::CampaignKind::fot ? fot_schedule(plan) : waveform_schedule(plan);
    double x = segs.empty() ? 0.0 : segs.front().target_mm;  // the preamble's end: the rig starts there
    if (model) model->reset(), v.peak_force_N = std::abs(model->step(x));
    for (const Segment& s : segs) {
      const double rate = s.rate_mm_s > 0 ? s.rate_mm_s : plan.ramp_rate_mm_s;
      v.duration_s += std::abs(s.target_mm - x) / rate + s.dwell_s;
      v.peak_speed_mm_s = std::max(v.peak_speed_mm_s, rate);
      if (model) {  // along the ramp, so that a peak inside it is seen
        constexpr int kSteps = 16;
        for (int k = 1; k <= kSteps; ++k) v.peak_force_N = std::max(v.peak_force_N, std::abs(model->step(x + (s.target_mm - x) * k / kSteps)));
      }
      x = s.target_mm;
    }
    if (plan.design.adaptive) {  // the coarse rows' ramps are the start of a budget the design may spend whole
      for (const Segment& s : segs)
        if (s.kind == SegmentKind::rise) v.duration_s -= domain::row_seconds(plan, s.target_mm - plan.lo_mm) - domain::kRowSettle_s;
      v.duration_s += plan.design.budget_s;
      v.design_budget_s = plan.design.budget_s;
    }
    if (plan.kind == domain::CampaignKind::fot)
      v.nodes = static_cast<std::size_t>(plan.subdivisions) * static_cast<std::size_t>(plan.subdivisions + 1) / 2 *
                static_cast<std::size_t>(std::max(plan.repeats, 1));
  }
  v.samples = v.duration_s * plan.sample_rate_hz;
  v.kind = plan.kind;
  v.sample_rate_hz = plan.sample_rate_hz;
  v.force_limit_N = plan.limits.force_max_N;
  return v;
}

}  // namespace hystlab::daemon
