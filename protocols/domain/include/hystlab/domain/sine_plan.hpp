#pragma once
// A sine plan as vibration engineers write one (docs/DAEMON.md, "sine"):
//   {"kind": "sine",
//    "sweep": {"from_hz": 5, "to_hz": 80, "steps": 24, "spacing": "log"}     stepped (or "frequencies_hz": [...])
//          or {"from_hz": 5, "to_hz": 80, "rate_oct_min": 2}                continuous (or "rate_hz_s")
//    or "dwell": {"frequency_hz": 17, "cycles": 2000, "track": "phase", "phase_deg": -90,
//                 "tolerance_deg": 5, "max_windows": 60}                    a (resonance) dwell
//    "direction": "up" | "down" | "up-down",
//    "amplitudes_mm": [0.01, 0.1]        base amplitudes (peak), each swept in turn ("amplitude_mm": one)
//    "settle_cycles": 10                  or "settle": {"change": "2 %", "consecutive": 2, "min_cycles": 30, "max_cycles": 400}
//    "measured_cycles": 10,
//    "control": {"tolerance": "5 %", "warning": "10 %", "abort": "30 %", "gain": 0.7, "window_cycles": 4,
//                "converge": "1 %", "max_windows": 12, "max_drive_ratio": 4, "start_level": 0.5,
//                "abort_windows": 3} or false (open loop: the drive is the demand)
//    "jump_threshold": "10 %",            up and down differing by more than this is a jump
//    "resonance": {"half_power_points": 5, "max_steps": 40} or true,   stepped: refine each pass's peak
//    "isolator": {"table": 7, ...}}       predicted with this isolator, not the rig's (daemon/isolator.hpp)
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace hystlab::domain {

enum class SweepDirection : std::uint8_t { up, down, up_down };
[[nodiscard]] const char* to_string(SweepDirection d) noexcept;

// Closed-loop base amplitude, as a sine controller holds it: after each window of window_cycles
// cycles the measured base amplitude is compared with the demand, and the drive is corrected by
// gain × the relative error (gain 1: at once; below 1: the compression of a controller's loop:
// the error falls by a factor 1 − gain a window, i.e. 20·log10(1/(1 − gain)) dB per window of
// window_cycles cycles; 0.7 and 4 cycles: 10.5 dB per 4 cycles). The loop corrects until the
// error is within converge_pct, and keeps correcting while the step settles; tolerance, warning
// and abort are alarm bands, not where correction stops.
struct SineControl {
  bool closed = true;
  double tolerance_pct = 5, warning_pct = 10, abort_pct = 30, gain = 0.7;
  // A step settles and is measured once the base is this close to the demand (stop 31's loop
  // stopped at the tolerance, approached from below: 45 of 51 points measured 3.8 to 4.5 % low).
  double converge_pct = 1;
  int window_cycles = 4;
  int max_windows = 12;        // control windows per step; then it is measured anyway, with a warning
  double max_drive_ratio = 4;  // the drive never exceeds this times the demand
  // The campaign's first step, with no response learnt yet, starts at this fraction of the demand
  // as its drive (-6 dB), from below, as controllers start a level: the table's response is not
  // known and an overshoot is what trips abort bands and can harm a specimen. Every later step
  // starts at the drive the response learnt at its frequency asks for (never dropped).
  double start_level = 0.5;
  // Windows in a row beyond the abort band that trip it (one while measuring). A lightly damped
  // isolator rings at its own frequency after every change, and the table moves with it: at
  // 16 Hz after 18 Hz the simulated one's base read +40 % and +34 % in its first two 4-cycle
  // windows (the ringing at 17.7 Hz inside the fit's resolution), then settled.
  int abort_windows = 3;
  // The loop check before a stepped sweep's first pass (0: none): every planned frequency driven
  // at this fraction of the plan's smallest amplitude (-12 dB), up, until the table's response
  // there stops changing, so that every step starts at the drive its own frequency needs. Without
  // it a step across the isolator's resonance starts at the drive learnt on the other side: the
  // simulated table's response changes 2.5 times between 17 and 18.5 Hz, and the base read 22 %
  // of its demand for a window there.
  double pretest_level = 0.25;
};

// When a step's response has settled: after `cycles` cycles at the step's final drive, or (until)
// once the mass amplitude changes by less than change_pct between `consecutive` + 1 successive
// windows, counted after min_cycles, within max_cycles. The minimum is there because a lightly
// damped isolator's free vibration beats with the forced response near its resonance, and at
// the beat's crest successive windows agree: with none, the simulated isolator (ζ = 0.02, a
// decay time of 0.45 s) was measured at 23.1 where its steady ratio is 13.4 (18.2 Hz).
struct SineSettle {
  int cycles = 10;
  bool until = false;
  double change_pct = 2;
  int consecutive = 2, min_cycles = 30, max_cycles = 400;
};

// Resonance refinement (stepped passes): after a pass's planned steps, steps are added around
// its highest peak, round by round (models::next_resonance_steps), until its half-power band
// holds half_power_points points, so Q is measured rather than bounded; at most max_steps added
// a pass (then said, with what was reached). The page's default 24 log steps read "Q ≥ 10.5"
// for the simulated isolator whose Q is about 25.
struct SineResonance {
  bool refine = false;
  int half_power_points = 5, max_steps = 40;
};

// A dwell: one frequency held for `cycles` cycles at each amplitude, each window of
// measured_cycles a point. Tracking the phase ("track": "phase"), the frequency is moved window
// by window until the mass's phase against the base is phase_deg (−90°: a linear isolator's
// natural frequency, as resonance dwells for fatigue and damping tests hold it) within
// tolerance_deg, and kept there; the cycles count from then. Not there within max_windows
// windows: said, and the dwell ends. Tracking moves the frequency at most kRange either way of
// frequency_hz: the envelope and the sample-rate rule are checked over that range.
struct SineDwell {
  static constexpr double kRange = 1.25;
  bool on = false, track_phase = false;
  double frequency_hz = 0, phase_deg = -90, tolerance_deg = 5;
  int cycles = 0, max_windows = 60;
};

struct SinePlan {
  std::vector<double> frequencies_hz;  // stepped: the frequencies, ascending
  bool continuous = false;
  double from_hz = 0, to_hz = 0, rate_oct_min = 0, rate_hz_s = 0;  // continuous: one of the two rates
  SweepDirection direction = SweepDirection::up;
  std::vector<double> amplitudes_mm;
  SineSettle settle;
  int measured_cycles = 10;
  SineControl control;
  double jump_threshold_pct = 10;
  SineResonance resonance;
  SineDwell dwell;  // on: frequencies_hz holds its one (starting) frequency
  // The isolator to predict with, as written (the daemon builds it: a stored table by id needs
  // its store); null: the rig's.
  nlohmann::json isolator;
  [[nodiscard]] double max_amplitude_mm() const;
  [[nodiscard]] double lowest_hz() const { return continuous ? from_hz : dwell.track_phase ? dwell.frequency_hz / SineDwell::kRange : frequencies_hz.front(); }
  [[nodiscard]] double highest_hz() const { return continuous ? to_hz : dwell.track_phase ? dwell.frequency_hz * SineDwell::kRange : frequencies_hz.back(); }
};

// One pass of a sweep: one amplitude, one direction.
struct SweepPass {
  double amplitude_mm = 0;
  bool up = true;
};
[[nodiscard]] std::vector<SweepPass> sweep_passes(const SinePlan& p);
// A stepped pass's frequencies in the order they are driven.
[[nodiscard]] std::vector<double> pass_frequencies(const SinePlan& p, const SweepPass& pass);
// Nominal duration (s): every step's control, settle and measurement at its nominal length (a
// continuous pass: its frequency span at its rate, plus the first settle).
[[nodiscard]] double nominal_duration_s(const SinePlan& p);
// One stepped step's nominal seconds at f: the control windows from the start level to the
// tolerance (each with its cycle of transient), the settle (its minimum and the criterion's
// windows, or the fixed cycles) and the measurement.
[[nodiscard]] double step_nominal_s(const SinePlan& p, double f);
// Whether the plan starts with the loop check (control.pretest_level): a closed-loop stepped
// sweep of two frequencies or more; its frequencies, ascending; its nominal seconds (each
// frequency: two windows that agree, each with its cycle of transient).
[[nodiscard]] bool has_pretest(const SinePlan& p);
[[nodiscard]] std::vector<double> pretest_frequencies(const SinePlan& p);
[[nodiscard]] double pretest_nominal_s(const SinePlan& p);
// The number of steps (points) of the plan: stepped: every frequency of every pass; continuous:
// about one point per measured window.
[[nodiscard]] std::size_t step_count(const SinePlan& p);

// Parses the sine fields of a plan (throws PlanError naming the field); sample_rate_hz bounds
// the frequencies (at least 8 samples a cycle).
[[nodiscard]] SinePlan parse_sine_plan(const nlohmann::json& j, double sample_rate_hz);

}  // namespace hystlab::domain
