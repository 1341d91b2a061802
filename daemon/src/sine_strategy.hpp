#pragma once
// Sine campaigns on a shaker, as a sine controller runs them (internal to the daemon): each pass
// (one base amplitude, one direction) is either stepped (each frequency: the base amplitude
// brought to the demand in closed loop, the response settled, then measured) or continuous (the
// frequency moves every cycle at the plan's rate, each measured window a point). Every window is
// fitted against the drive's own phase (integrated over the commanded frequencies), so a
// continuous sweep is measured as exactly as a dwell; the mass response is fitted with its
// harmonics, and how far it is from a sine (THD) is a result of its own. The result of each step
// is stored as it comes. sine_strategy.cpp: the samples, the windows and the base's control;
// sine_steps.cpp: the steps, the changes between them, the refinement, the dwell, the points.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
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

class SineStrategy final : public Strategy {
 public:
  static constexpr double kTwoPi = 2 * std::numbers::pi;

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

  bool on_shaker(Loop& L, const drivers::ShakerSample& s) override;

  // Held (zero drive) while paused: the samples say so.
  void on_pause(Loop& L, double) override { L.drive_mm = 0; }

  // The step is taken again from its start (a pause, a held link): the response has changed.
  void on_resume(Loop& L, double t, bool) override;

  [[nodiscard]] bool done() const override { return pass_ >= passes_.size(); }
  [[nodiscard]] CampaignPhase phase() const override;

  void fill_finish(Loop& L, FinishJob& fj) override;

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
  [[nodiscard]] bool cycle_loop() const;
  bool on_cycle(Loop& L, double t, double a);
  // False: the drive write failed.
  bool cycle_correction(Loop& L, double t, double a, bool& corrected);

  // A step (stepped pass) or the start of a continuous pass: drive at the learnt response.
  bool begin_step(Loop& L, double t);

  // A new level more than a factor kRampStep from the one before (the next pass's amplitude) is
  // reached in steps of kRampStep a control window, from the last level: a hysteretic isolator's
  // state is its amplitude history, and a jump of ×10 is a shock, not a sweep's level.
  // After a pause or a held link (zero drive) the level is ramped to from a quarter of it
  // (12 dB, two windows). last_level_ moves to a level once it is reached, so a ramp cut short
  // starts again from where it was.
  void start_ramp();

  // A ramp window: the next level (the last: on to control at the pass's own).
  bool after_ramp(Loop& L, double t);

  // The loop check (sine_pretest.hpp): each frequency at its level, corrected as a step is, until
  // its response holds; then the first pass, ramped to from the check's level. A pause or a held
  // link during the check restarts its frequency at the check's own level (small on purpose), so
  // the first pass ramps from that level, never from a quarter of its own (resumed_: a ×80 jump
  // with amplitudes [0.2, 0.005], found in review).
  bool pretest_step(Loop& L, double t);
  bool after_pretest(Loop& L, double t, const ControlVerdict& v, double base, const LearntResponse& phases);
  // The phases a check's window learns for the step changes (sine_change.hpp): the mass's against
  // the base's in (-3π/2, π/2] (a lag beyond 180° far above the resonance stays one), and against
  // the drive's.
  static LearntResponse learnt_phases(const models::HarmonicFit& b, const models::HarmonicFit& m);

  // A check's window against the level about to be driven (the first pass's): only a base above
  // its bands counts. The check's own level is far below them on purpose, so a base under the
  // demand is never an alarm here, whatever the windows before it (a frequency's under-demand
  // windows once counted towards an abort after another frequency had read within).
  ControlVerdict against_demand(ControlVerdict v, double base) const;

  bool open(Mode m, int skip_cycles, int cycles);

  bool to_settle();

  bool to_measure();

  // Seconds left at the pace so far: the plan's nominal time not yet done, stretched by how much
  // longer the steps done took than theirs (per step: a 5 Hz step is ten times a 50 Hz one, and
  // counting steps alike put the default sweep's first estimate at 513 s for 282 s).
  double eta(double t) const;

  bool on_window(Loop& L, double t);

  // Warning and abort bands. Too much motion counts at once; too little only once the loop has
  // had its chance (the step's base reached tolerance once, or the drive is at its cap, or the
  // step is being measured): each step starts below its target on purpose (BaseControl::start).
  // A warning is said once per step; control.abort_windows windows in a row beyond the abort
  // band (one while measuring) stop the drive and end the campaign with the reason.
  bool check_band(Loop& L, double t, const ControlVerdict& v, double base);

  bool redrive(Loop& L, double t, const ControlVerdict& v);

  // A drive write the rig did not take: a lost answer holds the table and the step is taken again
  // when the rig answers (Loop::command_failed); the campaign goes on unless it was ended.
  static bool going(const Loop& L) { return L.result.end == CampaignEnd::none; }

  // The measured window is the step's point, if its base was within control.converge of the
  // demand (a 10-cycle window read 5.00 % where the 4-cycle control windows had read 4.9 %, and
  // 1.14 % after windows within 1 %: bench_shaker); else the loop corrects and the step is
  // settled and measured again, while it has windows.
  bool after_measure(Loop& L, double t, const models::HarmonicFit& b, const models::HarmonicFit& m, const ControlVerdict& v);

  // Corrected until the base is within control.converge of the demand (open loop: at once).
  bool after_control(Loop& L, double t, const ControlVerdict& v);

  bool after_settle(Loop& L, double t, const ControlVerdict& v, double mass);

  // A continuous pass: each window is a point; the drive is corrected for the next window at once.
  bool after_sweep_window(Loop& L, double t, const models::HarmonicFit& b, const models::HarmonicFit& m, const ControlVerdict& v);

  // A dwell (the plan's "dwell"), from its settled start: each window a point; tracking the
  // phase, the frequency moves until the phase is the target within the tolerance, and the
  // cycles count from then.
  bool start_dwell();

  bool after_dwell_window(Loop& L, double t, const models::HarmonicFit& b, const models::HarmonicFit& m, const ControlVerdict& v);

  bool end_dwell(Loop& L, double t);

  // A cycle of a continuous pass has gone by: the next frequency at the plan's rate.
  bool sweep_frequency(Loop& L, double t);

  bool next_step(Loop& L, double t);

  // From this step's frequency to the next one's, within a pass (sine_change.hpp): a burst that
  // moves the drive's phase across the resonance, else a glide; then the step itself.
  bool start_change(Loop& L, double t);

  // The drive for the change's segment: a glide's at the level learnt at its frequency, with the
  // correction the cycle loop has made so far; a burst's at the new step's level.
  bool drive_change(Loop& L, double t, double next);

  // A change's sample: at the end of its segment the next one, or the step. A glide measured by
  // the cycle loop moves on with its cycles (on_cycle), each segment one of them.
  bool change_segment(Loop& L, double t);
  bool change_moved(Loop& L, double t) { return change_.active() ? drive_change(L, t, freqs_[step_]) : begin_step(L, t); }

  // A stepped pass's frequencies in the order driven (into reserved storage).
  void load_pass();

  // After a pass's steps, the plan's resonance refinement: the next round of steps around the
  // pass's peak, driven in the pass's direction (true: some were added). A round costs a sort of
  // the pass's points (tens), once per round, not per sample.
  bool refine(Loop& L);

  // The refinement is over: said when the band does not hold the points asked, with why.
  void unresolved(Loop& L, int want);

  bool retake(Loop& L, double t, const std::string& hole);

  void store_point(Loop& L, double t, const models::HarmonicFit& b, const models::HarmonicFit& m, const ControlVerdict& v);

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

}  // namespace hystlab::daemon
