// Issue 41's figure: rig time to a given held-out RMS, adaptive against uniform, on the simulated
// SMA spring (Table 1 at 0.05 N of noise) in process on the fake clock, at the daemon's 1 kHz and
// 0.5 mm/s. Uniform FOT campaigns n = 12, 24, 48 and an adaptive one (6 coarse rows, 400 s of
// budget, tops on 48 subdivisions); every table scored on the uniform n = 24 campaign's
// validation run (the same input every campaign drives, on one specimen's record). Prints the
// adaptive campaign's error against rig time after every row, the uniform points, and the rig
// time the adaptive campaign took to reach each uniform campaign's error as a ratio of that
// campaign's (target: at most 0.5 for n = 24 and n = 48). Validation runs are not counted. Then
// `hystlab design`'s rows for a target on the n = 12 table, driven as a plan of their nodes: does
// the held-out error reach the target the design estimated it would?
#include <cstdio>
#include <optional>
#include <string>

#include "../daemon/adaptive_world.hpp"
#include "hystlab/models/fot_design.hpp"

using namespace hystlab;
using namespace hystlab::test;

int main() {
  constexpr double kRate = 1000;
  struct Point {
    int n;
    double rig_s, heldout_N, lsq_N;
  };
  std::vector<Point> uniform;
  daemon::Columns v;
  std::optional<models::EverettTable> t12;
  for (int n : {24, 12, 48}) {
    World w(kRate);
    const Outcome o = w.run(plan_at_rate(n, kRate));
    if (o.result.end != daemon::CampaignEnd::completed) {
      std::printf("uniform n=%d did not complete: %s\n", n, o.result.reason.c_str());
      return 1;
    }
    if (n == 24) v = w.samples(o.result.validation_run_id);
    if (n == 12) t12 = w.table(o.result);
    uniform.push_back(
        {n, o.rig_s, models::score_table(w.table(o.result), v.x, v.f).overall.rms, models::score_table(w.table(o.result, true), v.x, v.f).overall.rms});
  }
  const json plan = adaptive_plan(6, 400, 0, 0.01, kRate);
  World a(kRate);
  const Outcome ad = a.run(plan);
  if (ad.result.end != daemon::CampaignEnd::completed) {
    std::printf("the adaptive campaign did not complete: %s\n", ad.result.reason.c_str());
    return 1;
  }
  const std::vector<double> held = heldout_by_step(a, ad, plan, v);
  std::printf("adaptive FOT campaign, error against rig time (held-out RMS on the uniform n=24 campaign's validation run)\n");
  std::printf("%5s %9s %13s %13s %9s  %s\n", "rows", "rig s", "held-out N", "estimate N", "next mm", "why");
  for (std::size_t k = 0; k < ad.design.size(); ++k) {
    const domain::DesignEvent& e = ad.design[k];
    std::printf("%5lld %9.1f %13.4f %13.4f %9.3f  %s\n", static_cast<long long>(e.rows), e.rig_s, held[k], e.estimated_rms_N, e.alpha_mm,
                e.stopped.empty() ? e.why.c_str() : ("stopped: " + e.stopped).c_str());
  }
  std::printf("force noise read from the rows: %.4f N; rig time %.1f s for %zu rows; its least-squares table (on the rows' grid): held-out %.4f N\n",
              ad.design.front().noise_N, ad.rig_s, tops(ad).size(), models::score_table(a.table(ad.result, true), v.x, v.f).overall.rms);
  std::printf("\n%-18s %9s %13s %26s %8s\n", "uniform (fot table)", "rig s", "held-out N", "adaptive reached it at s", "ratio");
  for (const Point& p : uniform) {
    double at = -1;
    for (std::size_t k = 0; k < held.size() && at < 0; ++k)
      if (held[k] <= p.heldout_N) at = ad.design[k].rig_s;
    if (at < 0)
      std::printf("fot n=%-12d %9.1f %13.4f %26s %8s\n", p.n, p.rig_s, p.heldout_N, "not reached", "-");
    else
      std::printf("fot n=%-12d %9.1f %13.4f %26.1f %8.2f%s\n", p.n, p.rig_s, p.heldout_N, at, at / p.rig_s,
                  p.n == 12 ? "" : (at / p.rig_s <= 0.5 ? "  (target <= 0.5: met)" : "  (target <= 0.5: NOT met)"));
  }
  std::printf("uniform campaigns' least-squares tables, held-out:");
  for (const Point& p : uniform) std::printf("  n=%d %.4f N", p.n, p.lsq_N);
  std::printf("\n");
  // `hystlab design --table T12.json --budget-s 300 --target-rms-n 1.0 --ramp-mm-s 0.5 --settle-s 1`
  // on the uniform n = 12 table, driven as a plan of its nodes on a fresh specimen.
  models::DesignOptions o;
  o.ramp_mm_s = 0.5, o.settle_s = 1.0, o.budget_s = 300, o.target_rms_N = 1.0;
  const models::Design d = models::design_rows(*t12, {}, o);
  json suggested = plan_at_rate(12, kRate);
  suggested.erase("subdivisions");
  suggested.erase("range_mm");
  suggested["nodes_mm"] = d.nodes;
  World s(kRate);
  const Outcome so = s.run(suggested);
  if (so.result.end != daemon::CampaignEnd::completed) {
    std::printf("the suggested design's campaign did not complete: %s\n", so.result.reason.c_str());
    return 1;
  }
  const double suggested_held = models::score_table(s.table(so.result), v.x, v.f).overall.rms;
  std::printf("\nhystlab design on the n=12 table (%.4f N), target 1.0 N: %zu rows more (%s), estimated %.4f N; driven: %.1f s, held-out %.4f N%s\n",
              uniform[1].heldout_N, d.rows.size(), d.stopped.c_str(), d.rows.empty() ? d.rms_before_N : d.rows.back().rms_after_N, so.rig_s, suggested_held,
              suggested_held <= o.target_rms_N ? "  (target reached)" : "  (target NOT reached)");
  return 0;
}
