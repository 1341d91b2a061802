#pragma once
// What a vibration engineer reads off a transmissibility sweep: the resonance (frequency, peak,
// half-power bandwidth and Q where the sweep reaches the half-power points) and, for a sweep
// taken up and down at one amplitude, the band where the two directions differ: the jump of a
// softening or hardening (here: hysteretic) isolator, which a linear plant never shows.
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
