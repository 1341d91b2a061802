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
  L.event("quality", {{"run", m.run ? m.run : r.run_id},
                      {"samples", samples},
                      {"missed_deadlines", r.missed_deadlines - m.missed},
                      {"late_wakeups", r.late_wakeups - m.late},
                      {"dropped", dropped},
                      {"lost_samples", h.lost_samples - m.health.lost_samples},
                      {"io_errors", h.total_errors() - m.health.total_errors()},
                      {"timeouts", h.errors_of(drivers::RigError::timeout) - m.health.errors_of(drivers::RigError::timeout)},
                      {"reconnects", h.reconnects - m.health.reconnects},
                      {"gaps", r.gaps - m.gaps},
                      {"gap_total_s", r.gap_total_s - m.gap_total_s},
                      {"longest_gap_s", m.longest_gap_s},
                      {"rig_seconds", span},
                      {"rate_hz", span > 0 && samples > 1 ? static_cast<double>(samples - 1) / span : 0.0},
                      {"requested_rate_hz", L.plan.sample_rate_hz},
                      {"time_scale", L.ctx.time_scale},
                      // the host samples at the plan's rate in wall time: a simulator time_scale
                      // times faster than real time gives that much less in rig time
                      {"expected_rate_hz", L.plan.sample_rate_hz / (L.ctx.time_scale > 0 ? L.ctx.time_scale : 1.0)}});
}

}  // namespace hystlab::daemon
