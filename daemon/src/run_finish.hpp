#pragma once
// The evaluations during a run (internal to the campaign runner).
#include <string>

#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/models/online_table_builder.hpp"

namespace hystlab::daemon {

// After a descent: the partial table against the samples so far (at most kEvaluationSamples of
// them, evenly spread), per branch, stored as a "fit" event. Scored in the background (the
// finisher's thread): the acquisition thread copies the partial table and shares the record's
// chunks, O(n² + chunks), never the samples.
inline constexpr std::size_t kEvaluationSamples = 65536;
void post_evaluation(RunnerContext& ctx, std::int64_t campaign, const models::OnlineTableBuilder& builder, const RunSeries& series, const std::string& now);

}  // namespace hystlab::daemon
