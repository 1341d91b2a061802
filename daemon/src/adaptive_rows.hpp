#pragma once
// An adaptive FOT campaign's rows after the coarse ones (issue 41), for the ramp strategy on the
// rig's thread: when the rows queued so far are measured, the next row from the design's rule
// (models/adaptive_fot.hpp), or the end of the design, once, with the event that says why.
// The choice is O(n²) on the table of the rows measured (n ≤ the finest grid's): it is made
// inline at the row's end, while the frame dwells at δmin, so a shutdown or an abort never waits
// for it, and a resumed campaign chooses from the same nodes.
#include <optional>
#include <vector>

#include "hystlab/daemon/run_series.hpp"
#include "hystlab/daemon/sequencer.hpp"
#include "hystlab/domain/events.hpp"
#include "hystlab/domain/plan.hpp"
#include "hystlab/models/adaptive_fot.hpp"

namespace hystlab::daemon {

class AdaptiveRows {
 public:
  explicit AdaptiveRows(const domain::Plan& plan);
  // The next row's two segments (rise, descent), or nullopt when the design stops (then over()).
  // The force noise is estimated once, from the series' last samples (slow ramps: the rows, and
  // on a resume the earlier attempt's with the preamble). A row chosen again (driven, and still
  // not measured whole after its retakes) ends the design: it would be chosen for ever.
  std::optional<std::vector<Segment>> next(const models::OnlineTableBuilder& fine, const RunSeries& series, domain::DesignEvent& event);
  // A resumed campaign: whether the design had stopped on these nodes (judged without the noise).
  [[nodiscard]] bool stopped_before(const models::OnlineTableBuilder& fine) const;
  [[nodiscard]] bool over() const noexcept { return over_; }
  // The rows the design chose in this attempt (fine-grid nodes), for their retakes.
  [[nodiscard]] const std::vector<int>& chosen() const noexcept { return chosen_; }

 private:
  const domain::Plan& plan_;
  models::AdaptiveOptions options_;
  std::optional<double> noise_;
  std::vector<int> chosen_;
  bool over_ = false;
};

}  // namespace hystlab::daemon
