#pragma once
// The knees of one branch of a loop: three straight lines, continuous, fitted by least squares to
// the branch's force against displacement. The two knots are the tangent intersections of
// neighbouring lines, which on a superelastic loop are the transformation points (loading: Ms, Mf;
// unloading, in increasing displacement: Af, As), as in the simplified model's four points.
#include <optional>
#include <span>

namespace hystlab::models {

struct BranchKnees {
  double lower_mm = 0, lower_N = 0, upper_mm = 0, upper_N = 0;  // the knots, lower < upper
  double slope_start = 0, slope_middle = 0, slope_end = 0;      // N/mm, in increasing displacement
  double rms_N = 0;                                             // of the three-line fit
  double line_rms_N = 0;                                        // of one straight line, for comparison
  double lo_mm = 0, hi_mm = 0;                                  // the branch's displacement range
  // A branch has knees when three lines fit it much better than one, its middle is softer than
  // both ends (a plateau), and each of the three spans 5 % of the branch at least: a loop that
  // turns inside its plateau has two lines, and its "upper knee" would be the rounding of a corner.
  [[nodiscard]] bool has_plateau() const noexcept {
    const double twentieth = 0.05 * (hi_mm - lo_mm);
    return rms_N < 0.5 * line_rms_N && slope_middle < 0.7 * slope_start && slope_middle < 0.7 * slope_end && lower_mm - lo_mm >= twentieth &&
           upper_mm - lower_mm >= twentieth && hi_mm - upper_mm >= twentieth;
  }
};

// The branch's samples in any order of displacement; at least 10, finite, spanning a displacement range.
// At most kMaxPoints samples are used (evenly taken). The knots are found by a grid search over the
// branch's range refined three times (to 1/40,000 of the range). nullopt when the branch is too short.
[[nodiscard]] std::optional<BranchKnees> fit_branch_knees(std::span<const double> displacement, std::span<const double> force);
inline constexpr std::size_t kMaxKneePoints = 400;

}  // namespace hystlab::models
