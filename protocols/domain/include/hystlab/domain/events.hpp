#pragma once
// A campaign's events, typed: each kind is a struct with its fields, and one to_json/from_json
// (the HYSTLAB_EVENT list below). The daemon writes them, db stores their detail as text, web
// and the CLI decode them here: a field renamed in one place is renamed everywhere, or fails to
// build. docs/API.md lists the same kinds and fields (tests/protocols/test_events.cpp checks it).
//
// The stored detail is this JSON, the same as before these structs existed (no migration): a
// field missing from an older detail keeps its default; a field of the wrong type is an error
// that names the kind and the field. A NaN is stored as null and read back as NaN.
#include <array>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace hystlab::domain {

// A hole in the time axis of a run (rig time).
struct GapEvent {
  double from_s = NAN, to_s = NAN, length_ms = NAN;
};
// A run's holes, summed up at its end.
struct GapsEvent {
  std::int64_t count = 0;
  double total_ms = NAN, longest_ms = NAN;
};
// The safe ramp arrived.
struct SafeEvent {
  double position_mm = NAN, target_mm = NAN, seconds = NAN;
};
// The limits a campaign runs under (the plan's, tightened to the rig's).
struct LimitsEvent {
  std::array<double, 2> displacement_mm{NAN, NAN};
  double force_N = NAN, rate_mm_s = NAN, safe_position_mm = NAN, safe_rate_mm_s = NAN, in_position_mm = NAN;
};
// A run's acquisition figures, at its end.
struct QualityEvent {
  std::int64_t run = 0, samples = 0, missed_deadlines = 0, late_wakeups = 0, dropped = 0, lost_samples = 0, io_errors = 0, timeouts = 0, reconnects = 0,
               gaps = 0;
  double gap_total_s = 0, longest_gap_s = 0, rig_seconds = 0, rate_hz = 0, requested_rate_hz = NAN, time_scale = 1, expected_rate_hz = NAN;
};
// One training cycle (major loop): its figures and their change from the cycle before.
struct ShakedownEvent {
  std::int64_t cycle = 0, consecutive = 0;
  double peak_force_N = NAN, energy_Nmm = NAN, damping_ratio = NAN, secant_stiffness_N_mm = NAN;
  bool stable = false;
  std::optional<double> peak_change_pct, energy_change_pct;  // none on the first cycle
};
// Training is over.
struct TrainingEvent {
  std::int64_t cycles = 0;
  bool stable = false, until = false;
  std::string why;
};
// The validation input begins (its own run).
struct ValidationEvent {
  std::int64_t run = 0, reversals = 0;
  std::uint64_t seed = 0;
  std::vector<double> points_mm;
  std::string why;
};
// Measured again: FOT rows with a hole (rows, round) or a sine step's window (frequency_hz, attempt).
struct RetakeEvent {
  std::optional<std::vector<std::int64_t>> rows;
  std::optional<std::int64_t> round, attempt;
  std::optional<double> frequency_hz;
  std::string why;
};
// An adaptive FOT campaign's design after a row (models/adaptive_fot.hpp): the next row's top and
// why, or why it stops (stopped), with the table's estimated held-out RMS and the rig time spent.
struct DesignEvent {
  std::int64_t rows = 0;  // rows measured whole
  double alpha_mm = NAN, estimated_rms_N = NAN, noise_N = NAN, spent_s = NAN, next_s = NAN, budget_s = NAN, target_rms_N = NAN;
  double rig_s = NAN;  // rig seconds since the campaign's run began (its preamble and training included)
  std::string why, stopped;
  std::vector<double> nodes_mm;  // the grid of the rows measured
};
// A sine step (or a continuous pass) begins.
struct SineStepEvent {
  std::int64_t k = 0, of = 0, pass = 0, passes = 0;
  double frequency_hz = NAN, amplitude_mm = NAN, drive_mm = NAN, eta_s = NAN;
  std::string direction;          // "up" or "down"
  std::string change;             // how the drive came from the step before: "glide", "burst", "jump"; "start": a pass's first
  double shift_deg = NAN;         // a burst's phase shift of the drive
  std::int64_t glide_cycles = 0;  // a glide's frequencies (cycles, unless it waited for the base)
};
// A measured point of a sweep (also a row of sine_points).
struct TransmissibilityEvent {
  std::int64_t k = 0, of = 0, pass = 0, harmonics = 0, control_windows = 0, settle_cycles = 0;
  double frequency_hz = NAN, amplitude_mm = NAN, drive_mm = NAN, base_amplitude_mm = NAN, base_phase_rad = NAN, mass_amplitude_mm = NAN, mass_phase_rad = NAN,
         ratio = NAN, phase_rad = NAN, thd = NAN, control_error_pct = NAN, t_s = NAN, eta_s = NAN;
  std::string direction, band;
};
// A sweep's end.
struct SweepDoneEvent {
  std::int64_t points = 0, of = 0, warnings = 0;
  double seconds = NAN, nominal_seconds = NAN;
  std::string predicted_with;
};
// The base amplitude left the abort band: the sweep stopped.
struct ControlAbortEvent {
  double frequency_hz = NAN, demand_mm = NAN, base_mm = NAN, error_pct = NAN, drive_mm = NAN;
};
// The base amplitude left the tolerance (once per step).
struct ControlWarningEvent {
  double frequency_hz = NAN, demand_mm = NAN, base_mm = NAN, error_pct = NAN;
  std::string band;
};
// The demand was not reached in the windows allowed ("while": "measuring" when measured anyway).
struct ControlUnreachedEvent {
  double frequency_hz = NAN, demand_mm = NAN, error_pct = NAN, drive_mm = NAN;
  std::int64_t windows = 0;
  bool limited = false;
  std::optional<std::string> while_;  // JSON "while"
};
// The response did not settle in the cycles allowed: measured anyway.
struct UnsettledEvent {
  double frequency_hz = NAN, change_pct = NAN;
  std::int64_t cycles = 0;
};
// A pass's resonance refinement stopped short of the half-power points asked (the plan's
// "resonance"): where the peak was, what its band held, and why no more steps were added.
struct ResonanceUnresolvedEvent {
  std::int64_t pass = 0, band_points = 0, wanted = 0, added = 0;
  double frequency_hz = NAN, amplitude_mm = NAN;
  std::string why;
};
// A dwell's end (the plan's "dwell"): where it held, for how long, and how well. Tracking the
// phase: the frequency it ended at, the mean phase of the windows since it was found, and the
// windows beyond the tolerance since; not found within max_windows: locked false.
struct DwellEvent {
  std::int64_t pass = 0, cycles = 0, windows = 0, out_of_tolerance = 0;
  double amplitude_mm = NAN, start_hz = NAN, frequency_hz = NAN, phase_deg = NAN, target_deg = NAN;
  bool locked = false;
  std::string track;
};
// The loop check's end (control.pretest_level): its frequencies driven at level_mm, the windows
// it took, the rig seconds, the frequencies whose response had not settled in its windows, and
// the table's response (base per unit of drive) it learnt, lowest and highest.
struct PretestEvent {
  std::int64_t frequencies = 0, windows = 0, unsettled = 0;
  double level_mm = NAN, seconds = NAN, response_min = NAN, response_max = NAN;
};
// The partial table scored on the run so far (after a descent); accuracy as models::accuracy_json.
struct FitEvent {
  std::int64_t nodes = 0, required = 0;
  nlohmann::json accuracy = nlohmann::json::object();
};
// The rig's envelope when the campaign was handed to it: a load frame's or a shaker's fields.
struct EnvelopeEvent {
  std::optional<std::array<double, 2>> stroke_mm, frequency_hz;
  std::optional<double> force_N, speed_mm_s, accel_mm_s2, displacement_mm, velocity_mm_s, accel_g;
};
// The specimen and notes, as changed.
struct RecordEvent {
  std::string specimen, notes;
};
// The table the campaign recommends.
struct RecommendationEvent {
  std::int64_t table = 0, n = 0;
  std::string method, why;
};
// A command to the campaign, sent or refused: plain text, not JSON ("pause", or why it was refused).
struct CommandEvent {
  std::string text;
};

using CampaignEvent =
    std::variant<GapEvent, GapsEvent, SafeEvent, LimitsEvent, QualityEvent, ShakedownEvent, TrainingEvent, ValidationEvent, RetakeEvent, DesignEvent,
                 SineStepEvent, TransmissibilityEvent, SweepDoneEvent, ControlAbortEvent, ControlWarningEvent, ControlUnreachedEvent, UnsettledEvent,
                 ResonanceUnresolvedEvent, DwellEvent, PretestEvent, FitEvent, EnvelopeEvent, RecordEvent, RecommendationEvent, CommandEvent>;

// Its stored kind ("gap", "control_unreached").
[[nodiscard]] std::string_view kind_of(const CampaignEvent& e) noexcept;
// Its stored detail: the JSON text, or a command's text.
[[nodiscard]] std::string encode(const CampaignEvent& e);
// The detail as the API shows it: an object, or a command's text as a JSON string.
[[nodiscard]] nlohmann::json detail_json(const CampaignEvent& e);

// A stored event read back. nullopt with error empty: a kind this version does not know (a
// "state" event, or one written by a newer hystlabd): the caller keeps its text. nullopt with an
// error: a known kind whose detail does not fit ("quality: field 'samples' must be a whole number").
[[nodiscard]] std::optional<CampaignEvent> decode_event(std::string_view kind, std::string_view detail, std::string& error);

// The schema: every kind with its fields, in the order written (docs/API.md, "Campaign events").
struct EventKind {
  std::string_view kind;
  std::vector<std::string_view> fields;
};
[[nodiscard]] const std::vector<EventKind>& event_kinds();

}  // namespace hystlab::domain
