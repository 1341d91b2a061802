// What a run's data can be trusted for, stored with it (the API shows it beside each result). A
// FOT campaign's run and its validation run are measured apart: until stop 27 the campaign's run
// was given both runs' samples and the validation run none.
#include <cmath>

#include "acquisition_loop.hpp"

namespace hystlab::daemon {

void mark_run(Loop& L, std::int64_t run) {
  const RunnerResult& r = L.result;
  L.mark = {run,
            r.samples,
            r.missed_deadlines,
            r.late_wakeups,
            L.ctx.writer.stats().dropped_full - L.dropped_before,
            r.gaps,
            r.gap_total_s,
            0.0,
            std::isnan(L.last_t) ? 0.0 : L.last_t,
            L.ctx.rig.health()};
}

void record_quality(Loop& L) {
  const drivers::IoHealthSnapshot h = L.ctx.rig.health();
  const RunnerResult& r = L.result;
  const Loop::RunMark& m = L.mark;
  const double span = std::isnan(L.last_t) ? 0.0 : L.last_t - m.t0;
  const std::uint64_t samples = r.samples - m.samples;
  const std::uint64_t dropped = L.ctx.writer.stats().dropped_full - L.dropped_before - m.dropped;
  domain::QualityEvent q;
  const auto count = [](std::uint64_t n) { return static_cast<std::int64_t>(n); };
  q.run = m.run ? m.run : r.run_id, q.samples = count(samples), q.missed_deadlines = count(r.missed_deadlines - m.missed);
  q.late_wakeups = count(r.late_wakeups - m.late), q.dropped = count(dropped), q.lost_samples = count(h.lost_samples - m.health.lost_samples);
  q.io_errors = count(h.total_errors() - m.health.total_errors());
  q.timeouts = count(h.errors_of(drivers::RigError::timeout) - m.health.errors_of(drivers::RigError::timeout));
  q.reconnects = count(h.reconnects - m.health.reconnects), q.gaps = count(r.gaps - m.gaps);
  q.gap_total_s = r.gap_total_s - m.gap_total_s, q.longest_gap_s = m.longest_gap_s, q.rig_seconds = span;
  q.rate_hz = span > 0 && samples > 1 ? static_cast<double>(samples - 1) / span : 0.0;
  q.requested_rate_hz = L.plan.sample_rate_hz, q.time_scale = L.ctx.time_scale;
  // the host samples at the plan's rate in wall time: a simulator time_scale times faster than
  // real time gives that much less in rig time
  q.expected_rate_hz = L.plan.sample_rate_hz / (L.ctx.time_scale > 0 ? L.ctx.time_scale : 1.0);
  L.event(q);
}

}  // namespace hystlab::daemon
