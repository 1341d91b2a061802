#pragma once
// What a vibration engineer reads off a transmissibility sweep: the resonance (frequency, peak,
// half-power bandwidth and Q where the sweep reaches the half-power points) and, for a sweep
// taken up and down at one amplitude, the band where the two directions differ: the jump of a
// softening or hardening (here: hysteretic) isolator, which a linear plant never shows.
#include <cmath>
#include <optional>
#include <span>
#include <vector>

namespace hystlab::models {

struct SweepPoint {
  double frequency_hz = 0, ratio = 0, phase_rad = 0;
};

struct Resonance {
  double frequency_hz = 0, peak_ratio = 0;  // the sweep's highest point (refined by a parabola in log-log when resolved)
  double lower_hz = 0, upper_hz = 0;        // half-power points (ratio = peak/√2), 0 when the sweep ends before one
  double bandwidth_hz = 0, q = 0;           // upper − lower and f/bandwidth, 0 unless both points are inside the sweep
  bool at_edge = false;                     // the highest point is the sweep's first or last: the peak may lie beyond
  // A point on each side of the peak above the half-power level: the bandwidth is measured. Not
  // resolved (steps coarser than the peak), the bandwidth is at most what is given and Q at least.
  bool resolved = false;
};

// The highest point of the sweep (points in any order; none: fewer than 3 points or a ratio that
// is not positive and finite). The half-power points are interpolated in log f, log ratio.
[[nodiscard]] std::optional<Resonance> find_resonance(std::span<const SweepPoint> points);

// A stepped sweep's resonance refinement (a sine plan's "resonance"): the frequencies to
// measure next so that the half-power band of the sweep's highest peak holds at least `want`
// points, the Q then measured rather than bounded. Into `out`, ascending; empty when nothing is
// left to do: the band holds them (band_holds), the peak is at the sweep's edge (it may lie beyond), or a
// side never falls to half power inside the sweep. Each round narrows in on the peak:
// - unresolved (both neighbours of the highest point below half power: the peak lies between
//   them), want points across the half-power band that the parabola of 1/ratio² through the
//   three points implies (a linear isolator's 1/ratio² is nearly one near its peak); when that
//   parabola says nothing (opens downwards, its vertex outside the neighbours), want + 1 points
//   evenly in log f between the two neighbours, so the bracket shrinks by (want + 2)/2 a round;
// - resolved, want points evenly in log f across the half-power band as interpolated (the
//   chord across a peak crosses half power inside the true band: the points land in it);
//   once it holds want points, the midpoint of each gap still too wide (band_holds).
// A candidate within a quarter of the round's spacing of a point already measured is not added.
void next_resonance_steps(std::span<const SweepPoint> points, int want, std::vector<double>& out);
// How many points lie in r's half-power band (0 unless both half-power points were found).
[[nodiscard]] int points_in_band(const Resonance& r, std::span<const SweepPoint> points) noexcept;
// The refinement's goal: the highest peak resolved, its band holding `want` points, none of
// its neighbouring points (nor the top's) more than 2/want of the bandwidth apart.
[[nodiscard]] bool band_holds(std::span<const SweepPoint> points, int want);

// A step's equivalent viscous damping ratio from its hysteresis loop: ζ_eq = W_d / (4π W_s),
// W_d the loop's area ∮F dz over a cycle and W_s = ½·k'·Z² the elastic energy at its amplitude,
// with F = m·ω²·X_mass the force the springs and damper put on the mass and z = mass − base. On
// the measured fundamentals (ratio T and phase φ of mass against base), F/Z = m·ω²·T·e^{iφ}/(T·e^{iφ} − 1),
// and with δ its argument (the force's lead over the stroke, the loss angle) ζ_eq = tan(δ)/2:
// the loop's harmonics do not change its area against a sine stroke. A linear spring-damper's
// is ζ·f/f_n (ζ at its natural frequency); NaN when the ratio or phase is not finite.
[[nodiscard]] double equivalent_damping(double ratio, double phase_rad) noexcept;

struct Jump {
  double lo_hz = 0, hi_hz = 0;  // the frequencies between which up and down differ by more than the threshold
  double max_difference = 0;    // the largest |up − down| / max(up, down) there
  double up_jump_hz = 0;        // where the up sweep's ratio changes most between neighbouring points (geometric midpoint)
  double down_jump_hz = 0;      // and the down sweep's
};

// Up and down at one amplitude, each in any order; down is interpolated (log-log) at up's
// frequencies. threshold: a fraction (0.1: 10 %). Empty when the directions agree.
[[nodiscard]] std::vector<Jump> find_jumps(std::span<const SweepPoint> up, std::span<const SweepPoint> down, double threshold);

// A whole sweep: points of several amplitudes and directions, grouped into curves (one per
// amplitude and direction, in the order they came), each with its resonance, and for each
// amplitude swept both ways the jumps between the directions.
struct SweepCurvePoint {
  double amplitude_mm = 0;
  bool up = true;
  SweepPoint point;
};
struct SweepCurve {
  double amplitude_mm = 0;
  bool up = true;
  std::vector<SweepPoint> points;
  std::optional<Resonance> resonance;
  // The backbone's damping: equivalent_damping at the resonance, interpolated in log f between
  // the points either side of it (NaN without a resonance inside the sweep).
  double damping_at_resonance = NAN;
};
struct AmplitudeJumps {
  double amplitude_mm = 0;
  std::vector<Jump> jumps;
};
struct SweepReport {
  std::vector<SweepCurve> curves;
  std::vector<AmplitudeJumps> jumps;  // amplitudes swept up and down only
};
[[nodiscard]] SweepReport analyse_sweep(std::span<const SweepCurvePoint> points, double jump_threshold);

}  // namespace hystlab::models
