// The sine strategy's steps (sine_strategy.hpp): from one to the next (a glide or a burst,
// sine_change.hpp), the resonance refinement's rounds, the dwell, a step's point stored.
#include "sine_strategy.hpp"

namespace hystlab::daemon {

bool SineStrategy::after_sweep_window(Loop& L, double t, const models::HarmonicFit& b, const models::HarmonicFit& m, const ControlVerdict& v) {
  store_point(L, t, b, m, v);
  if (sweep_over_) {
    ++pass_;
    sweep_over_ = false;
    return pass_ < passes_.size() ? begin_step(L, t) : true;
  }
  if (s_.control.closed && !v.converged) {
    drive_ = v.next_drive_mm;
    if (!L.command_drive(t, f_, drive_)) return going(L);
  }
  return open(Mode::sweep, 0, s_.measured_cycles);
}

bool SineStrategy::start_dwell() {
  const domain::SineDwell& d = s_.dwell;
  dwell_ = DwellCount{};
  dwell_.locked = !d.track_phase;
  tracker_.start(d.phase_deg * std::numbers::pi / 180, d.frequency_hz / domain::SineDwell::kRange, d.frequency_hz * domain::SineDwell::kRange);
  return open(Mode::dwell, 0, s_.measured_cycles);
}

bool SineStrategy::after_dwell_window(Loop& L, double t, const models::HarmonicFit& b, const models::HarmonicFit& m, const ControlVerdict& v) {
  const domain::SineDwell& d = s_.dwell;
  const double phase = std::remainder(m.fundamental.phase_rad - b.fundamental.phase_rad, kTwoPi);
  const bool within = !d.track_phase || std::fabs(tracker_.error(phase)) * 180 / std::numbers::pi <= d.tolerance_deg;
  ++dwell_.windows;
  // Found once the phase is within the tolerance and the base at its demand (the window just
  // after the last big move still rings: the base read +3.7 % and −4.8 % there).
  dwell_.locked = dwell_.locked || (within && (v.converged || !s_.control.closed));
  if (dwell_.locked) {
    dwell_.cycles += s_.measured_cycles, dwell_.phase_sum_deg += phase * 180 / std::numbers::pi, ++dwell_.measured;
    if (!within) ++dwell_.out_of_tolerance;
  }
  // The windows still to come, for the progress ("k of N"): the search's were not planned.
  const auto left = dwell_.locked ? static_cast<std::size_t>(std::max<std::int64_t>(0, d.cycles - dwell_.cycles) / s_.measured_cycles) : 1;
  total_ = std::max(total_, static_cast<std::size_t>(points_) + 1 + left);
  store_point(L, t, b, m, v);
  if ((dwell_.locked && dwell_.cycles >= d.cycles) || (!dwell_.locked && dwell_.windows >= d.max_windows)) return end_dwell(L, t);
  const double f = d.track_phase ? tracker_.next(f_, phase) : f_;
  const bool moved = std::fabs(f - f_) > 1e-9 * f_, redrive = s_.control.closed && !v.converged;
  if (redrive) drive_ = v.next_drive_mm;
  f_ = f;
  if ((moved || redrive) && !L.command_drive(t, f_, drive_)) return going(L);
  return open(Mode::dwell, moved ? 1 : 0, s_.measured_cycles);
}

bool SineStrategy::end_dwell(Loop& L, double t) {
  const domain::SineDwell& d = s_.dwell;
  domain::DwellEvent ev;
  ev.pass = static_cast<std::int64_t>(pass_) + 1, ev.amplitude_mm = demand(), ev.track = d.track_phase ? "phase" : "none";
  ev.start_hz = d.frequency_hz, ev.frequency_hz = f_, ev.target_deg = d.track_phase ? d.phase_deg : NAN;
  ev.phase_deg = dwell_.measured > 0 ? dwell_.phase_sum_deg / static_cast<double>(dwell_.measured) : NAN;
  ev.cycles = dwell_.cycles, ev.windows = dwell_.windows, ev.out_of_tolerance = dwell_.out_of_tolerance, ev.locked = dwell_.locked;
  L.event(ev);
  if (!dwell_.locked) ++warnings_;
  ++step_;
  return next_step(L, t);
}

bool SineStrategy::sweep_frequency(Loop& L, double t) {
  const double sign = up() ? 1.0 : -1.0;
  const double next = s_.rate_oct_min > 0 ? f_ * std::exp2(sign * s_.rate_oct_min / 60.0 / f_) : f_ + sign * s_.rate_hz_s / f_;
  if (next > s_.to_hz || next < s_.from_hz) sweep_over_ = true;  // this window is the pass's last
  if (sweep_over_) return true;
  f_ = next;
  return L.command_drive(t, f_, drive_);
}

bool SineStrategy::next_step(Loop& L, double t) {
  if (step_ >= freqs_.size() && !refine(L)) {
    step_ = 0, ++pass_;
    if (pass_ < passes_.size()) load_pass();
  }
  if (pass_ >= passes_.size()) return true;
  if (step_ > 0 && s_.control.closed && !s_.dwell.on) return start_change(L, t);
  return begin_step(L, t);
}

bool SineStrategy::start_change(Loop& L, double t) {
  const double next = freqs_[step_];
  change_.plan(f_, next, w_.phase(), pre_.phases_at(f_), pre_.phases_at(next), s_.lowest_hz(), s_.highest_hz());
  change_how_ = change_.kind() == SineChange::Kind::burst ? "burst" : change_.kind() == SineChange::Kind::glide ? "glide" : "jump";
  change_shift_deg_ = change_.kind() == SineChange::Kind::burst ? change_.shift_rad() * 180 / std::numbers::pi : NAN;
  change_glide_ = change_.kind() == SineChange::Kind::glide ? change_.glide_cycles() : 0;
  if (!change_.active()) return begin_step(L, t);
  change_corr_ = 1.0;
  cycle_corrections_ = 0;  // the glide's own budget
  return drive_change(L, t, next);
}

bool SineStrategy::drive_change(Loop& L, double t, double next) {
  const bool glide = change_.kind() == SineChange::Kind::glide;
  if (glide && mode_ == Mode::change && f_ > 0) change_corr_ = std::clamp(drive_ / control_.start(f_, demand()), 1 / 1.5, 1.5);
  f_ = change_.frequency();
  // A burst: the new step's drive, or less where the table answers more at the burst's frequency
  // (the base never driven beyond its demand there: the plan's envelope was checked at the demand).
  const double level = glide ? control_.start(f_, demand()) * change_corr_ : std::min(control_.start(next, demand()), control_.start(f_, demand()));
  drive_ = std::min(level, s_.control.max_drive_ratio * demand());
  mode_ = Mode::change;
  if (!L.command_drive(t, f_, drive_)) return going(L);
  return true;
}

bool SineStrategy::change_segment(Loop& L, double t) {
  if (cycle_loop() || !change_.advance(w_.phase())) return true;
  return change_.active() ? drive_change(L, t, freqs_[step_]) : begin_step(L, t);
}

void SineStrategy::load_pass() {
  freqs_.clear(), pass_points_.clear(), added_ = 0;
  if (s_.continuous || pass_ >= passes_.size()) return;
  if (up())
    freqs_.insert(freqs_.end(), s_.frequencies_hz.begin(), s_.frequencies_hz.end());
  else
    freqs_.insert(freqs_.end(), s_.frequencies_hz.rbegin(), s_.frequencies_hz.rend());
}

bool SineStrategy::refine(Loop& L) {
  if (!s_.resonance.refine || s_.continuous) return false;
  const int want = s_.resonance.half_power_points, room = s_.resonance.max_steps - added_;
  models::next_resonance_steps(pass_points_, want, refine_next_);
  if (refine_next_.empty() || room <= 0) return unresolved(L, want), false;
  if (!up()) std::reverse(refine_next_.begin(), refine_next_.end());
  const auto n = std::min(refine_next_.size(), static_cast<std::size_t>(room));
  for (std::size_t k = 0; k < n; ++k) freqs_.push_back(refine_next_[k]), added_nominal_ += domain::step_nominal_s(s_, refine_next_[k]);
  added_ += static_cast<int>(n), total_ += n;
  return true;
}

void SineStrategy::unresolved(Loop& L, int want) {
  if (models::band_holds(pass_points_, want)) return;  // the refinement's own goal, not a second copy of it
  const auto r = models::find_resonance(pass_points_);
  const int in_band = r ? models::points_in_band(*r, pass_points_) : 0;
  const char* why = !r                                     ? "fewer than 3 points"
                    : r->at_edge                           ? "the peak is at the sweep's edge (it may lie beyond)"
                    : added_ >= s_.resonance.max_steps     ? "resonance.max_steps reached"
                    : r->lower_hz <= 0 || r->upper_hz <= 0 ? "a side of the peak never falls to half power inside the sweep"
                                                           : "no room left between the points measured";
  domain::ResonanceUnresolvedEvent ev;
  ev.pass = static_cast<std::int64_t>(pass_) + 1, ev.frequency_hz = r ? r->frequency_hz : NAN, ev.amplitude_mm = demand();
  ev.band_points = in_band, ev.wanted = want, ev.added = added_, ev.why = why;
  L.event(ev);
  ++warnings_;
}

bool SineStrategy::retake(Loop& L, double t, const std::string& hole) {
  if (++retakes_ > kMaxRetakes) {
    L.ctx.supervisor.hold(t, "no complete measurement: no drive");
    char buf[200];
    std::snprintf(buf, sizeof buf, "the measurement window at %g Hz was incomplete %d times (last: %s)", f_, kMaxRetakes + 1, hole.c_str());
    L.end(CampaignEnd::failed, buf);
    return false;
  }
  domain::RetakeEvent ev;
  ev.frequency_hz = f_, ev.attempt = retakes_ + 1, ev.why = hole;
  L.event(ev);
  w_.reopen();
  return true;
}

void SineStrategy::store_point(Loop& L, double t, const models::HarmonicFit& b, const models::HarmonicFit& m, const ControlVerdict& v) {
  const double ratio = m.fundamental.amplitude / b.fundamental.amplitude;
  const double phase = std::remainder(m.fundamental.phase_rad - b.fundamental.phase_rad, kTwoPi);
  const double f = s_.continuous ? w_.mean_frequency() : f_;
  ++points_;
  if (s_.dwell.on)
    nominal_done_ += s_.measured_cycles / f_;  // a dwell's window, not a step
  else if (!s_.continuous)
    nominal_done_ += domain::step_nominal_s(s_, f_);
  domain::TransmissibilityEvent rec;
  rec.k = points_, rec.of = static_cast<std::int64_t>(total_), rec.pass = static_cast<std::int64_t>(pass_) + 1;
  rec.frequency_hz = f, rec.amplitude_mm = demand(), rec.direction = up() ? "up" : "down", rec.drive_mm = drive_;
  rec.base_amplitude_mm = b.fundamental.amplitude, rec.base_phase_rad = b.fundamental.phase_rad;
  rec.mass_amplitude_mm = m.fundamental.amplitude, rec.mass_phase_rad = m.fundamental.phase_rad;
  rec.ratio = ratio, rec.phase_rad = phase, rec.thd = m.thd, rec.harmonics = m.harmonics;
  rec.control_error_pct = v.error_pct, rec.band = to_string(v.band), rec.control_windows = control_windows_;
  rec.settle_cycles = s_.settle.until ? settled_cycles_ : s_.settle.cycles, rec.t_s = t, rec.eta_s = eta(t);
  // A dwell's windows are predicted once per frequency (within 0.5 %): a 2000-cycle dwell is
  // not 200 simulations on the finisher.
  const bool predict = !s_.dwell.on || steps_.empty() || std::fabs(steps_.back().second.frequency_hz / f - 1) > 0.005 ||
                       std::fabs(steps_.back().second.base_amplitude_mm / b.fundamental.amplitude - 1) > 0.05;
  if (predict) steps_.push_back({points_, PredictStep{f, b.fundamental.amplitude, settled_cycles_ + s_.settle.cycles, s_.measured_cycles}});
  if (!s_.continuous && pass_points_.size() < pass_points_.capacity()) pass_points_.push_back({f, ratio, phase});
  db::SinePointRow row{points_, f, demand(), b.fundamental.amplitude, m.fundamental.amplitude, ratio, phase, rec.direction, domain::encode(rec)};
  const auto run = L.result.run_id, id = L.job.id;
  const std::string now = L.ctx.now_iso();
  L.ctx.writer.post([run, row, id, now, rec = domain::CampaignEvent(std::move(rec))](db::Store& st) {
    st.add_sine_point(run, row);
    st.add_event(id, rec, now);
  });
}

}  // namespace hystlab::daemon
