// Sine campaigns on a shaker, as a sine controller runs them: each pass (one base amplitude, one
// direction) is either stepped (each frequency: the base amplitude brought to the demand in
// closed loop, the response settled, then measured) or continuous (the frequency moves every
// cycle at the plan's rate, each measured window a point). Every window is fitted against the
// drive's own phase (integrated over the commanded frequencies), so a continuous sweep is
// measured as exactly as a dwell; the mass response is fitted with its harmonics, and how far it
// is from a sine (THD) is a result of its own. The result of each step is stored as it comes.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "acquisition_loop.hpp"
#include "hystlab/daemon/base_control.hpp"
#include "hystlab/models/sine_fit.hpp"
#include "hystlab/models/sweep_analysis.hpp"
#include "phase_tracker.hpp"
#include "sine_change.hpp"
#include "sine_cycle.hpp"
#include "sine_pretest.hpp"
#include "sine_window.hpp"

namespace hystlab::daemon {
namespace {
constexpr double kTwoPi = 2 * std::numbers::pi;

class SineStrategy final : public Strategy {
 public:
  explicit SineStrategy(const domain::Plan& p)
      : plan_(p),
        s_(p.sine),
        control_(p.sine.control),
        pre_(p.sine),
        passes_(domain::sweep_passes(p.sine)),
        total_(domain::step_count(p.sine)),
        nominal_s_(domain::nominal_duration_s(p.sine)),
        pretest_nominal_s_(domain::pretest_nominal_s(p.sine)) {
    // Every buffer a pass fills at its largest, here: none grows on the acquisition thread.
    const std::size_t most = s_.frequencies_hz.size() + static_cast<std::size_t>(s_.resonance.refine ? s_.resonance.max_steps : 0);
    freqs_.reserve(most), pass_points_.reserve(most), refine_next_.reserve(static_cast<std::size_t>(s_.resonance.half_power_points) + 2);
    load_pass();
  }

  bool on_shaker(Loop& L, const drivers::ShakerSample& s) override {
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

  // Held (zero drive) while paused: the samples say so.
  void on_pause(Loop& L, double) override { L.drive_mm = 0; }

  // The step is taken again from its start (a pause, a held link): the response has changed.
  void on_resume(Loop& L, double t, bool) override {
    w_.restart(t);
    change_.cancel();  // from zero drive: the step itself, ramped to
    resumed_ = true;   // from zero drive: the level is ramped to again
    if (pre_.active()) {
      pre_.restart_frequency();
      (void)pretest_step(L, t);
    } else if (pass_ < passes_.size()) {
      (void)begin_step(L, t);
    }
  }

  [[nodiscard]] bool done() const override { return pass_ >= passes_.size(); }
  [[nodiscard]] CampaignPhase phase() const override {
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

  void fill_finish(Loop& L, FinishJob& fj) override {
    fj.isolator = L.job.isolator;
    fj.sine_steps = steps_;
    if (points_ > 0)
      L.event(domain::SweepDoneEvent{points_, static_cast<std::int64_t>(total_), warnings_, last_t_ - t0_, nominal_s_,
                                     L.job.isolator ? L.job.isolator->describe : ""});
  }

 private:
  enum class Mode { pretest, ramp, control, settle, measure, sweep, dwell, change };
  // Amplitude changes between the plan's levels go at most ×2 (6 dB) a control window.
  static constexpr double kRampStep = 2.0;

  // The base amplitude aimed at: the pass's, or while ramping to it, the ramp's level.
  double demand() const { return ramping_ ? ramp_level_ : passes_[pass_].amplitude_mm; }
  bool up() const { return passes_[pass_].up; }
  int harmonics(double f) const { return std::clamp(static_cast<int>(0.45 * plan_.sample_rate_hz / f), 1, 5); }

  // The base every cycle while a step is brought to its demand (control and settle windows): a
  // cycle beyond the tolerance band is corrected at once, as a sine controller's loop runs every
  // cycle, and the windows' loop (every window_cycles cycles) takes over at the new drive. A
  // window is too slow for a lightly damped isolator ringing after a step across its resonance:
  // its reaction on the table beats with the drive, and the base read 64 % of its demand for a
  // window there (stop 34); with the cycle loop 81-84 % (stop 36), the ringing's first cycle or
  // two outrunning any loop that measures a cycle before it acts, which the step changes now
  // avoid (sine_change.hpp). It also runs through a glide's cycles, which it moves on. Bounded: the
  // control gain towards the demand, at most ×1.5 a cycle, within the drive's cap,
  // kMaxCycleCorrections a step; only with kCycleSamples a cycle or more.
  [[nodiscard]] bool cycle_loop() const {
    const bool gliding = mode_ == Mode::change && change_.kind() == SineChange::Kind::glide;
    return s_.control.closed && (mode_ == Mode::control || mode_ == Mode::settle || gliding) && plan_.sample_rate_hz >= kCycleSamples * f_;
  }
  bool on_cycle(Loop& L, double t, double a) {
    bool corrected = false;
    if (!cycle_correction(L, t, a, corrected)) return false;
    if (mode_ == Mode::change) return change_.after_cycle((a / demand() - 1) * 100) ? change_moved(L, t) : true;  // a glide's cycle
    if (!corrected) return true;
    if (mode_ == Mode::settle) stable_ = 0, prev_mass_ = NAN;  // settled again from here
    return open(Mode::control, 1, s_.control.window_cycles);
  }
  // False: the drive write failed.
  bool cycle_correction(Loop& L, double t, double a, bool& corrected) {
    const double d = demand();
    if (!(a > 0) || cycle_corrections_ >= kMaxCycleCorrections || std::fabs(a / d - 1) * 100 <= s_.control.tolerance_pct) return true;
    const double next = std::clamp(drive_ * std::clamp(1 + s_.control.gain * (d / a - 1), 1 / 1.5, 1.5), 1e-6, s_.control.max_drive_ratio * d);
    if (std::fabs(next - drive_) <= 1e-9 * drive_) return true;  // at the cap already
    drive_ = next;
    ++cycle_corrections_;
    corrected = true;
    return L.command_drive(t, f_, drive_);
  }

  // A step (stepped pass) or the start of a continuous pass: drive at the learnt response.
  bool begin_step(Loop& L, double t) {
    f_ = s_.continuous ? (up() ? s_.from_hz : s_.to_hz) : freqs_[step_];
    start_ramp();
    drive_ = control_.start(f_, demand());
    cycle_corrections_ = 0;
    control_windows_ = 0, settled_cycles_ = 0, stable_ = 0, abort_windows_ = 0, retakes_ = 0, warned_ = false, established_ = !s_.control.closed;
    prev_mass_ = NAN;
    if (!L.command_drive(t, f_, drive_)) return going(L);
    L.event(domain::SineStepEvent{points_ + 1, static_cast<std::int64_t>(total_), static_cast<std::int64_t>(pass_) + 1,
                                  static_cast<std::int64_t>(passes_.size()), f_, passes_[pass_].amplitude_mm, drive_, eta(t), up() ? "up" : "down", change_how_,
                                  change_shift_deg_, change_glide_});
    change_how_ = "start", change_shift_deg_ = NAN, change_glide_ = 0;
    if (ramping_) return open(Mode::ramp, 1, s_.control.window_cycles);
    if (s_.control.closed) return open(Mode::control, 1, s_.control.window_cycles);
    return to_settle();
  }

  // A new level more than a factor kRampStep from the one before (the next pass's amplitude) is
  // reached in steps of kRampStep a control window, from the last level: a hysteretic isolator's
  // state is its amplitude history, and a jump of ×10 is a shock, not a sweep's level.
  // After a pause or a held link (zero drive) the level is ramped to from a quarter of it
  // (12 dB, two windows). last_level_ moves to a level once it is reached, so a ramp cut short
  // starts again from where it was.
  void start_ramp() {
    const double target = passes_[pass_].amplitude_mm;
    const double from = resumed_ ? target / (kRampStep * kRampStep) : last_level_;
    resumed_ = false;
    ramping_ = from > 0 && (target > kRampStep * from * (1 + 1e-9) || target * kRampStep < from * (1 - 1e-9));
    if (ramping_) ramp_level_ = target > from ? from * kRampStep : from / kRampStep;
    if (!ramping_) last_level_ = target;
  }

  // A ramp window: the next level (the last: on to control at the pass's own).
  bool after_ramp(Loop& L, double t) {
    const double target = passes_[pass_].amplitude_mm;
    ramp_level_ = target > ramp_level_ ? std::min(target, ramp_level_ * kRampStep) : std::max(target, ramp_level_ / kRampStep);
    ramping_ = ramp_level_ != target;
    if (!ramping_) last_level_ = target;
    drive_ = control_.start(f_, demand());
    if (!L.command_drive(t, f_, drive_)) return going(L);
    return open(ramping_ ? Mode::ramp : Mode::control, 1, s_.control.window_cycles);
  }

  // The loop check (sine_pretest.hpp): each frequency at its level, corrected as a step is, until
  // its response holds; then the first pass, ramped to from the check's level. A pause or a held
  // link during the check restarts its frequency at the check's own level (small on purpose), so
  // the first pass ramps from that level, never from a quarter of its own (resumed_: a ×80 jump
  // with amplitudes [0.2, 0.005], found in review).
  bool pretest_step(Loop& L, double t) {
    f_ = pre_.frequency();
    drive_ = control_.start(f_, pre_.level());
    abort_windows_ = 0, retakes_ = 0, warned_ = false, established_ = false, resumed_ = false;
    if (!L.command_drive(t, f_, drive_)) return going(L);
    return open(Mode::pretest, 1, s_.control.window_cycles);
  }
  bool after_pretest(Loop& L, double t, const ControlVerdict& v, double base, const LearntResponse& phases) {
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
  // The phases a check's window learns for the step changes (sine_change.hpp): the mass's against
  // the base's in (-3π/2, π/2] (a lag beyond 180° far above the resonance stays one), and against
  // the drive's.
  static LearntResponse learnt_phases(const models::HarmonicFit& b, const models::HarmonicFit& m) {
    double tr = std::remainder(m.fundamental.phase_rad - b.fundamental.phase_rad, kTwoPi);
    if (tr > std::numbers::pi / 2) tr -= kTwoPi;
    return {m.fundamental.amplitude / b.fundamental.amplitude, tr, m.fundamental.phase_rad};
  }

  // A check's window against the level about to be driven (the first pass's): only a base above
  // its bands counts. The check's own level is far below them on purpose, so a base under the
  // demand is never an alarm here, whatever the windows before it (a frequency's under-demand
  // windows once counted towards an abort after another frequency had read within).
  ControlVerdict against_demand(ControlVerdict v, double base) const {
    v.error_pct = (base / demand() - 1) * 100, v.limited = false;
    v.band = v.error_pct > 0 ? control_.band_of(v.error_pct) : ControlBand::within;
    return v;
  }

  bool open(Mode m, int skip_cycles, int cycles) {
    mode_ = m;
    w_.open(skip_cycles, cycles);
    return true;
  }

  bool to_settle() {
    if (s_.settle.until) return open(Mode::settle, 0, s_.control.window_cycles);
    if (s_.settle.cycles > 0) return open(Mode::settle, 0, s_.settle.cycles);
    return to_measure();
  }

  bool to_measure() {
    if (s_.dwell.on) return start_dwell();
    if (!s_.continuous) return open(Mode::measure, 0, s_.measured_cycles);
    next_cycle_ = w_.phase() + kTwoPi;
    return open(Mode::sweep, 0, s_.measured_cycles);
  }

  // Seconds left at the pace so far: the plan's nominal time not yet done, stretched by how much
  // longer the steps done took than theirs (per step: a 5 Hz step is ten times a 50 Hz one, and
  // counting steps alike put the default sweep's first estimate at 513 s for 282 s).
  double eta(double t) const {
    const double nominal = nominal_s_ + added_nominal_;
    const double done = s_.continuous ? (total_ > 0 ? nominal * static_cast<double>(points_) / static_cast<double>(total_) : 0.0) : nominal_done_;
    const double pace = done > 0 ? std::max(1.0, (t - t0_) / done) : 1.0;
    return std::max(0.0, nominal - done) * pace;
  }

  bool on_window(Loop& L, double t) {
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

  // Warning and abort bands. Too much motion counts at once; too little only once the loop has
  // had its chance (the step's base reached tolerance once, or the drive is at its cap, or the
  // step is being measured): each step starts below its target on purpose (BaseControl::start).
  // A warning is said once per step; control.abort_windows windows in a row beyond the abort
  // band (one while measuring) stop the drive and end the campaign with the reason.
  bool check_band(Loop& L, double t, const ControlVerdict& v, double base) {
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

  bool redrive(Loop& L, double t, const ControlVerdict& v) {
    drive_ = v.next_drive_mm;
    if (!L.command_drive(t, f_, drive_)) return going(L);
    return open(Mode::control, 1, s_.control.window_cycles);
  }

  // A drive write the rig did not take: a lost answer holds the table and the step is taken again
  // when the rig answers (Loop::command_failed); the campaign goes on unless it was ended.
  static bool going(const Loop& L) { return L.result.end == CampaignEnd::none; }

  // The measured window is the step's point, if its base was within control.converge of the
  // demand (a 10-cycle window read 5.00 % where the 4-cycle control windows had read 4.9 %, and
  // 1.14 % after windows within 1 %: bench_shaker); else the loop corrects and the step is
  // settled and measured again, while it has windows.
  bool after_measure(Loop& L, double t, const models::HarmonicFit& b, const models::HarmonicFit& m, const ControlVerdict& v) {
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

  // Corrected until the base is within control.converge of the demand (open loop: at once).
  bool after_control(Loop& L, double t, const ControlVerdict& v) {
    if (v.converged || !s_.control.closed) return to_settle();
    if (++control_windows_ >= s_.control.max_windows) {
      if (v.band != ControlBand::within) L.event(domain::ControlUnreachedEvent{f_, demand(), v.error_pct, drive_, control_windows_, v.limited, std::nullopt});
      return to_settle();
    }
    return redrive(L, t, v);
  }

  bool after_settle(Loop& L, double t, const ControlVerdict& v, double mass) {
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

  // A continuous pass: each window is a point; the drive is corrected for the next window at once.
  bool after_sweep_window(Loop& L, double t, const models::HarmonicFit& b, const models::HarmonicFit& m, const ControlVerdict& v) {
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

  // A dwell (the plan's "dwell"), from its settled start: each window a point; tracking the
  // phase, the frequency moves until the phase is the target within the tolerance, and the
  // cycles count from then.
  bool start_dwell() {
    const domain::SineDwell& d = s_.dwell;
    dwell_ = DwellCount{};
    dwell_.locked = !d.track_phase;
    tracker_.start(d.phase_deg * std::numbers::pi / 180, d.frequency_hz / domain::SineDwell::kRange, d.frequency_hz * domain::SineDwell::kRange);
    return open(Mode::dwell, 0, s_.measured_cycles);
  }

  bool after_dwell_window(Loop& L, double t, const models::HarmonicFit& b, const models::HarmonicFit& m, const ControlVerdict& v) {
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

  bool end_dwell(Loop& L, double t) {
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

  // A cycle of a continuous pass has gone by: the next frequency at the plan's rate.
  bool sweep_frequency(Loop& L, double t) {
    const double sign = up() ? 1.0 : -1.0;
    const double next = s_.rate_oct_min > 0 ? f_ * std::exp2(sign * s_.rate_oct_min / 60.0 / f_) : f_ + sign * s_.rate_hz_s / f_;
    if (next > s_.to_hz || next < s_.from_hz) sweep_over_ = true;  // this window is the pass's last
    if (sweep_over_) return true;
    f_ = next;
    return L.command_drive(t, f_, drive_);
  }

  bool next_step(Loop& L, double t) {
    if (step_ >= freqs_.size() && !refine(L)) {
      step_ = 0, ++pass_;
      if (pass_ < passes_.size()) load_pass();
    }
    if (pass_ >= passes_.size()) return true;
    if (step_ > 0 && s_.control.closed && !s_.dwell.on) return start_change(L, t);
    return begin_step(L, t);
  }

  // From this step's frequency to the next one's, within a pass (sine_change.hpp): a burst that
  // moves the drive's phase across the resonance, else a glide; then the step itself.
  bool start_change(Loop& L, double t) {
    const double next = freqs_[step_];
    change_.plan(f_, next, w_.phase(), pre_.phases_at(f_), pre_.phases_at(next), s_.lowest_hz(), s_.highest_hz());
    change_how_ = change_.kind() == SineChange::Kind::burst ? "burst" : change_.kind() == SineChange::Kind::glide ? "glide" : "jump";
    change_shift_deg_ = change_.kind() == SineChange::Kind::burst ? change_.shift_rad() * 180 / std::numbers::pi : NAN;
    change_glide_ = change_.kind() == SineChange::Kind::glide ? change_.glide_cycles() : 0;
    if (!change_.active()) return begin_step(L, t);
    change_corr_ = 1.0;
    return drive_change(L, t, next);
  }

  // The drive for the change's segment: a glide's at the level learnt at its frequency, with the
  // correction the cycle loop has made so far; a burst's at the new step's level.
  bool drive_change(Loop& L, double t, double next) {
    const bool glide = change_.kind() == SineChange::Kind::glide;
    if (glide && mode_ == Mode::change && f_ > 0) change_corr_ = std::clamp(drive_ / control_.start(f_, demand()), 1 / 1.5, 1.5);
    f_ = change_.frequency();
    drive_ = std::min(control_.start(glide ? f_ : next, demand()) * (glide ? change_corr_ : 1.0), s_.control.max_drive_ratio * demand());
    mode_ = Mode::change;
    if (!L.command_drive(t, f_, drive_)) return going(L);
    return true;
  }

  // A change's sample: at the end of its segment the next one, or the step. A glide measured by
  // the cycle loop moves on with its cycles (on_cycle), each segment one of them.
  bool change_segment(Loop& L, double t) {
    if (cycle_loop() || !change_.advance(w_.phase())) return true;
    return change_.active() ? drive_change(L, t, freqs_[step_]) : begin_step(L, t);
  }
  bool change_moved(Loop& L, double t) { return change_.active() ? drive_change(L, t, freqs_[step_]) : begin_step(L, t); }

  // A stepped pass's frequencies in the order driven (into reserved storage).
  void load_pass() {
    freqs_.clear(), pass_points_.clear(), added_ = 0;
    if (s_.continuous || pass_ >= passes_.size()) return;
    if (up())
      freqs_.insert(freqs_.end(), s_.frequencies_hz.begin(), s_.frequencies_hz.end());
    else
      freqs_.insert(freqs_.end(), s_.frequencies_hz.rbegin(), s_.frequencies_hz.rend());
  }

  // After a pass's steps, the plan's resonance refinement: the next round of steps around the
  // pass's peak, driven in the pass's direction (true: some were added). A round costs a sort of
  // the pass's points (tens), once per round, not per sample.
  bool refine(Loop& L) {
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

  // The refinement is over: said when the band does not hold the points asked, with why.
  void unresolved(Loop& L, int want) {
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

  bool retake(Loop& L, double t, const std::string& hole) {
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

  void store_point(Loop& L, double t, const models::HarmonicFit& b, const models::HarmonicFit& m, const ControlVerdict& v) {
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

  const domain::Plan& plan_;
  const domain::SinePlan& s_;
  BaseControl control_;
  SinePretest pre_;
  std::vector<domain::SweepPass> passes_;
  std::vector<std::pair<std::int64_t, PredictStep>> steps_;
  std::vector<double> freqs_, refine_next_;      // this pass's frequencies (planned, then refined); a round's
  std::vector<models::SweepPoint> pass_points_;  // this pass's measured points (resonance refinement)
  int added_ = 0;                                // steps added to this pass
  struct DwellCount {
    std::int64_t cycles = 0, windows = 0, out_of_tolerance = 0, measured = 0;
    double phase_sum_deg = 0;
    bool locked = false;
  } dwell_;
  PhaseTracker tracker_;
  bool ramping_ = false, resumed_ = false;
  double ramp_level_ = 0, last_level_ = 0;  // the ramp's level now; the last level reached
  double added_nominal_ = 0;                // their nominal seconds (the ETA)
  std::size_t total_ = 0, pass_ = 0, step_ = 0;
  double nominal_s_, pretest_nominal_s_;  // the plan's nominal seconds, once: eta() runs every step on the loop's thread
  std::int64_t points_ = 0;
  static constexpr int kMaxRetakes = 3;
  static constexpr int kCycleSamples = 16, kMaxCycleCorrections = 64;
  CycleAmplitude cycle_;
  SineChange change_;
  std::string change_how_ = "start";  // how the step about to begin was reached (its sine_step event)
  double change_shift_deg_ = NAN, change_corr_ = 1.0;
  std::int64_t change_glide_ = 0;
  double cycle_drive_ = NAN, cycle_f_ = NAN;  // what the cycle being summed is driven at
  int cycle_corrections_ = 0;
  Mode mode_ = Mode::control;
  SineWindow w_;
  bool started_ = false, sweep_over_ = false, warned_ = false, established_ = false;
  double t0_ = 0, last_t_ = 0, f_ = 0, drive_ = 0, prev_mass_ = NAN, next_cycle_ = 0, nominal_done_ = 0;
  int control_windows_ = 0, settled_cycles_ = 0, stable_ = 0, abort_windows_ = 0, retakes_ = 0, warnings_ = 0;
};
}  // namespace

std::unique_ptr<Strategy> make_sine_strategy(Loop& L) { return std::make_unique<SineStrategy>(L.plan); }

}  // namespace hystlab::daemon
