#pragma once
// The end of a run and the evaluations during it (internal to the campaign runner).
#include <string>
#include <vector>

#include "hystlab/daemon/campaign_runner.hpp"
#include "hystlab/daemon/online_fot.hpp"
#include "hystlab/models/online_table_builder.hpp"

namespace hystlab::daemon {

struct RunSeries {  // the run's measured loop, kept for the fits (about 16 bytes per sample)
  std::vector<double> x, f;
  void add(double xi, double fi) {
    x.push_back(xi);
    f.push_back(fi);
  }
};

// After a descent: the partial table against every sample so far, per branch, stored as an event
// by the writer thread (the acquisition thread only copies).
void post_evaluation(db::SampleWriter& writer, std::int64_t campaign, const models::OnlineTableBuilder& builder,
                     const RunSeries& series, const std::string& now);

// Closes the run: the last node, the calibrated table with its accuracy, drift and provenance,
// and the constrained least-squares table from every sample.
void finish_run(RunnerResult& result, std::int64_t campaign, const Plan& plan, const models::OnlineTableBuilder* builder,
                OnlineFot* fot, const RunSeries& series, RunnerContext& ctx);

}  // namespace hystlab::daemon
