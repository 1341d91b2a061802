// The sine strategy's samples, windows and base control (sine_strategy.hpp).
#include "sine_strategy.hpp"

namespace hystlab::daemon {

bool SineStrategy::on_shaker(Loop& L, const drivers::ShakerSample& s) {
  if (done()) return true;  // the last pass is over (a block read brings samples past it)
  if (!started_) {
    started_ = true;
    t0_ = s.time_s;
    w_.restart(s.time_s);
    return pre_.active() ? pretest_step(L, s.time_s) : begin_step(L, s.time_s);
  }
  w_.advance(s.time_s, L.drive_hz);
  w_.collect(s.time_s, s.base_displacement_mm, s.mass_displacement_mm);
  if (cycle_loop()) {
    if (drive_ != cycle_drive_ || f_ != cycle_f_) cycle_.restart(w_.phase()), cycle_drive_ = drive_, cycle_f_ = f_;
    double a = NAN;
    if (cycle_.add(w_.phase(), s.base_displacement_mm, kCycleSamples, a) && !on_cycle(L, s.time_s, a)) return going(L);
  } else {
    cycle_drive_ = NAN;  // no sums while it does not run (measured windows, sweeps): afresh when it does
  }
  if (mode_ == Mode::change) return change_segment(L, s.time_s);
  if (mode_ == Mode::sweep && w_.phase() >= next_cycle_) {
    next_cycle_ += kTwoPi;
    if (!sweep_frequency(L, s.time_s)) return L.result.end == CampaignEnd::none;
  }
  if (!w_.complete()) return true;
  return on_window(L, s.time_s);
}

void SineStrategy::on_resume(Loop& L, double t, bool) {
  w_.restart(t);
  change_.cancel();  // from zero drive: the step itself, ramped to
  change_how_ = "start", change_shift_deg_ = NAN, change_glide_ = 0;
  resumed_ = true;  // from zero drive: the level is ramped to again
  if (pre_.active()) {
    pre_.restart_frequency();
    (void)pretest_step(L, t);
  } else if (pass_ < passes_.size()) {
    (void)begin_step(L, t);
  }
}

CampaignPhase SineStrategy::phase() const {
  switch (mode_) {
    case Mode::measure:
      return CampaignPhase::shaker_measure;
    case Mode::ramp:
      return CampaignPhase::shaker_ramp;
    case Mode::sweep:
      return CampaignPhase::shaker_sweep;
    case Mode::dwell:
      return CampaignPhase::shaker_dwell;
    case Mode::pretest:
      return CampaignPhase::shaker_check;
    case Mode::change:
      return CampaignPhase::shaker_change;
    default:
      return CampaignPhase::shaker_control;
  }
}

void SineStrategy::fill_finish(Loop& L, FinishJob& fj) {
  fj.isolator = L.job.isolator;
  fj.sine_steps = steps_;
  if (points_ > 0)
    L.event(domain::SweepDoneEvent{points_, static_cast<std::int64_t>(total_), warnings_, last_t_ - t0_, nominal_s_,
                                   L.job.isolator ? L.job.isolator->describe : ""});
}

bool SineStrategy::cycle_loop() const {
  const bool gliding = mode_ == Mode::change && change_.kind() == SineChange::Kind::glide;
  return s_.control.closed && (mode_ == Mode::control || mode_ == Mode::settle || gliding) && plan_.sample_rate_hz >= kCycleSamples * f_;
}

bool SineStrategy::on_cycle(Loop& L, double t, double a) {
  bool corrected = false;
  if (!cycle_correction(L, t, a, corrected)) return false;
  if (mode_ == Mode::change) return change_.after_cycle((a / demand() - 1) * 100, w_.phase()) ? change_moved(L, t) : true;  // a glide's cycle
  if (!corrected) return true;
  if (mode_ == Mode::settle) stable_ = 0, prev_mass_ = NAN;  // settled again from here
  return open(Mode::control, 1, s_.control.window_cycles);
}

bool SineStrategy::cycle_correction(Loop& L, double t, double a, bool& corrected) {
  const double d = demand();
  if (!(a > 0) || cycle_corrections_ >= kMaxCycleCorrections || std::fabs(a / d - 1) * 100 <= s_.control.tolerance_pct) return true;
  const double next = std::clamp(drive_ * std::clamp(1 + s_.control.gain * (d / a - 1), 1 / 1.5, 1.5), 1e-6, s_.control.max_drive_ratio * d);
  if (std::fabs(next - drive_) <= 1e-9 * drive_) return true;  // at the cap already
  drive_ = next;
  ++cycle_corrections_;
  corrected = true;
  return L.command_drive(t, f_, drive_);
}

bool SineStrategy::begin_step(Loop& L, double t) {
  f_ = s_.continuous ? (up() ? s_.from_hz : s_.to_hz) : freqs_[step_];
  start_ramp();
  drive_ = control_.start(f_, demand());
  cycle_corrections_ = 0;
  control_windows_ = 0, settled_cycles_ = 0, stable_ = 0, abort_windows_ = 0, retakes_ = 0, warned_ = false, established_ = !s_.control.closed;
  prev_mass_ = NAN;
  if (!L.command_drive(t, f_, drive_)) return going(L);
  L.event(domain::SineStepEvent{points_ + 1, static_cast<std::int64_t>(total_), static_cast<std::int64_t>(pass_) + 1, static_cast<std::int64_t>(passes_.size()),
                                f_, passes_[pass_].amplitude_mm, drive_, eta(t), up() ? "up" : "down", change_how_, change_shift_deg_, change_glide_});
  change_how_ = "start", change_shift_deg_ = NAN, change_glide_ = 0;
  if (ramping_) return open(Mode::ramp, 1, s_.control.window_cycles);
  if (s_.control.closed) return open(Mode::control, 1, s_.control.window_cycles);
  return to_settle();
}

void SineStrategy::start_ramp() {
  const double target = passes_[pass_].amplitude_mm;
  const double from = resumed_ ? target / (kRampStep * kRampStep) : last_level_;
  resumed_ = false;
  ramping_ = from > 0 && (target > kRampStep * from * (1 + 1e-9) || target * kRampStep < from * (1 - 1e-9));
  if (ramping_) ramp_level_ = target > from ? from * kRampStep : from / kRampStep;
  if (!ramping_) last_level_ = target;
}

bool SineStrategy::after_ramp(Loop& L, double t) {
  const double target = passes_[pass_].amplitude_mm;
  ramp_level_ = target > ramp_level_ ? std::min(target, ramp_level_ * kRampStep) : std::max(target, ramp_level_ / kRampStep);
  ramping_ = ramp_level_ != target;
  if (!ramping_) last_level_ = target;
  drive_ = control_.start(f_, demand());
  if (!L.command_drive(t, f_, drive_)) return going(L);
  return open(ramping_ ? Mode::ramp : Mode::control, 1, s_.control.window_cycles);
}

bool SineStrategy::pretest_step(Loop& L, double t) {
  f_ = pre_.frequency();
  drive_ = control_.start(f_, pre_.level());
  abort_windows_ = 0, retakes_ = 0, warned_ = false, established_ = false, resumed_ = false;
  if (!L.command_drive(t, f_, drive_)) return going(L);
  return open(Mode::pretest, 1, s_.control.window_cycles);
}

bool SineStrategy::after_pretest(Loop& L, double t, const ControlVerdict& v, double base, const LearntResponse& phases) {
  if (!pre_.window(base / drive_, phases)) {
    drive_ = v.next_drive_mm;
    if (!L.command_drive(t, f_, drive_)) return going(L);
    return open(Mode::pretest, 1, s_.control.window_cycles);
  }
  if (pre_.active()) return pretest_step(L, t);
  L.event(pre_.summary(t - t0_));
  nominal_done_ += pretest_nominal_s_;
  last_level_ = pre_.level();  // the first pass is ramped to from here
  return begin_step(L, t);
}

LearntResponse SineStrategy::learnt_phases(const models::HarmonicFit& b, const models::HarmonicFit& m) {
  double tr = std::remainder(m.fundamental.phase_rad - b.fundamental.phase_rad, kTwoPi);
  if (tr > std::numbers::pi / 2) tr -= kTwoPi;
  return {m.fundamental.amplitude / b.fundamental.amplitude, tr, m.fundamental.phase_rad};
}

ControlVerdict SineStrategy::against_demand(ControlVerdict v, double base) const {
  v.error_pct = (base / demand() - 1) * 100, v.limited = false;
  v.band = v.error_pct > 0 ? control_.band_of(v.error_pct) : ControlBand::within;
  return v;
}

bool SineStrategy::open(Mode m, int skip_cycles, int cycles) {
  mode_ = m;
  w_.open(skip_cycles, cycles);
  return true;
}

bool SineStrategy::to_settle() {
  if (s_.settle.until) return open(Mode::settle, 0, s_.control.window_cycles);
  if (s_.settle.cycles > 0) return open(Mode::settle, 0, s_.settle.cycles);
  return to_measure();
}

bool SineStrategy::to_measure() {
  if (s_.dwell.on) return start_dwell();
  if (!s_.continuous) return open(Mode::measure, 0, s_.measured_cycles);
  next_cycle_ = w_.phase() + kTwoPi;
  return open(Mode::sweep, 0, s_.measured_cycles);
}

double SineStrategy::eta(double t) const {
  const double nominal = nominal_s_ + added_nominal_;
  const double done = s_.continuous ? (total_ > 0 ? nominal * static_cast<double>(points_) / static_cast<double>(total_) : 0.0) : nominal_done_;
  const double pace = done > 0 ? std::max(1.0, (t - t0_) / done) : 1.0;
  return std::max(0.0, nominal - done) * pace;
}

bool SineStrategy::on_window(Loop& L, double t) {
  last_t_ = t;
  if (const std::string hole = w_.hole(); !hole.empty()) return retake(L, t, hole);
  const models::HarmonicFit b = w_.fit_base(), m = w_.fit_mass(harmonics(f_));
  if (!b.fundamental.ok || !m.fundamental.ok) return retake(L, t, "no sine fit");
  const bool check = mode_ == Mode::pretest;
  const ControlVerdict v = control_.update(s_.continuous ? w_.mean_frequency() : f_, check ? pre_.level() : demand(), drive_, b.fundamental.amplitude);
  if (!check_band(L, t, check ? against_demand(v, b.fundamental.amplitude) : v, b.fundamental.amplitude)) return false;
  switch (mode_) {
    case Mode::pretest:
      return after_pretest(L, t, v, b.fundamental.amplitude, learnt_phases(b, m));
    case Mode::ramp:
      return after_ramp(L, t);
    case Mode::control:
      return after_control(L, t, v);
    case Mode::settle:
      return after_settle(L, t, v, m.fundamental.amplitude);
    case Mode::measure:
      return after_measure(L, t, b, m, v);
    case Mode::sweep:
      return after_sweep_window(L, t, b, m, v);
    case Mode::dwell:
      return after_dwell_window(L, t, b, m, v);
    case Mode::change:
      return true;  // not reached: a change's samples go to change_segment
  }
  return true;
}

bool SineStrategy::check_band(Loop& L, double t, const ControlVerdict& v, double base) {
  // A dwell still looking for its phase moves the frequency every window: its base is
  // controlled as a step's, not yet measured.
  const bool measuring = mode_ == Mode::measure || mode_ == Mode::sweep || (mode_ == Mode::dwell && dwell_.locked);
  const bool counts = v.error_pct > 0 || established_ || v.limited || measuring || std::isnan(v.error_pct);
  if (v.band == ControlBand::within) established_ = true;
  if (counts && v.band == ControlBand::abort && (++abort_windows_ >= s_.control.abort_windows || measuring)) {
    char buf[240];
    std::snprintf(buf, sizeof buf, "control abort: the base amplitude was %.4g mm against the demand %.4g mm (error %+.1f %%, abort band ±%g %%) at %.4g Hz",
                  base, demand(), v.error_pct, s_.control.abort_pct, f_);
    L.event(domain::ControlAbortEvent{f_, demand(), base, v.error_pct, drive_});
    L.ctx.supervisor.hold(t, "control abort: no drive");
    L.drive_mm = 0;
    L.end(CampaignEnd::aborted, buf);
    return false;
  }
  if (!counts || v.band != ControlBand::abort) abort_windows_ = 0;
  if (counts && (v.band == ControlBand::warning || v.band == ControlBand::abort) && !warned_) {
    warned_ = true;
    ++warnings_;
    L.event(domain::ControlWarningEvent{f_, demand(), base, v.error_pct, to_string(v.band)});
  }
  return true;
}

bool SineStrategy::redrive(Loop& L, double t, const ControlVerdict& v) {
  drive_ = v.next_drive_mm;
  if (!L.command_drive(t, f_, drive_)) return going(L);
  return open(Mode::control, 1, s_.control.window_cycles);
}

bool SineStrategy::after_measure(Loop& L, double t, const models::HarmonicFit& b, const models::HarmonicFit& m, const ControlVerdict& v) {
  if (s_.control.closed && !v.converged && control_windows_ < s_.control.max_windows) {
    ++control_windows_;
    return redrive(L, t, v);
  }
  if (s_.control.closed && v.band != ControlBand::within)  // measured anyway: said
    L.event(domain::ControlUnreachedEvent{f_, demand(), v.error_pct, drive_, control_windows_, v.limited, "measuring"});
  store_point(L, t, b, m, v);
  ++step_;
  return next_step(L, t);
}

bool SineStrategy::after_control(Loop& L, double t, const ControlVerdict& v) {
  if (v.converged || !s_.control.closed) return to_settle();
  if (++control_windows_ >= s_.control.max_windows) {
    if (v.band != ControlBand::within) L.event(domain::ControlUnreachedEvent{f_, demand(), v.error_pct, drive_, control_windows_, v.limited, std::nullopt});
    return to_settle();
  }
  return redrive(L, t, v);
}

bool SineStrategy::after_settle(Loop& L, double t, const ControlVerdict& v, double mass) {
  // The base wandered off while the response settled (the load changed as it did): back to control.
  if (s_.control.closed && v.band != ControlBand::within && control_windows_ < s_.control.max_windows) {
    ++control_windows_;
    stable_ = 0, prev_mass_ = NAN;
    return redrive(L, t, v);
  }
  // Within tolerance but not at the demand: corrected as the response settles (a small change:
  // the settling goes on), as a controller's loop never stops.
  if (s_.control.closed && !v.converged && v.band == ControlBand::within && control_windows_ < s_.control.max_windows) {
    ++control_windows_;
    drive_ = v.next_drive_mm;
    if (!L.command_drive(t, f_, drive_)) return going(L);
    if (!s_.settle.until) return open(Mode::settle, 1, s_.settle.cycles);  // settled again at the new drive
  }
  if (!s_.settle.until) return to_measure();
  settled_cycles_ += s_.control.window_cycles;
  const double change = std::fabs(mass - prev_mass_) / std::max(prev_mass_, 1e-12) * 100;
  stable_ = change < s_.settle.change_pct && settled_cycles_ >= s_.settle.min_cycles ? stable_ + 1 : 0;
  prev_mass_ = mass;
  if (stable_ >= s_.settle.consecutive) return to_measure();
  if (settled_cycles_ >= s_.settle.max_cycles) {
    L.event(domain::UnsettledEvent{f_, change, settled_cycles_});
    return to_measure();
  }
  return open(Mode::settle, 0, s_.control.window_cycles);
}

std::unique_ptr<Strategy> make_sine_strategy(Loop& L) { return std::make_unique<SineStrategy>(L.plan); }

}  // namespace hystlab::daemon
